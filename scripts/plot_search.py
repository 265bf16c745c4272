#!/usr/bin/python3
"""Curves of a `morphfem search` run beside the voxel study's.

usage: plot_search.py SUMMARY.json OUT_DIR

For every experiment: left panel = this run (one colour per method), right panel =
the voxel study's hill climber on the same experiment (if its CSV is known); both
show the mean +/- one standard deviation over climbers (band) and the maximum
(dashed) of the best speed so far [BL/s] against generation. Writes
OUT_DIR/curves_<experiment>.png and OUT_DIR/curves.png (all experiments).
Needs Debian's python3-matplotlib (run with /usr/bin/python3).
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"hill": "tab:blue", "cmaes": "tab:red"}


def read_history(path):
    """Rows g = 0..G of the 'g,f_1,...,f_N' layout -> (generations, [[values per climber]])."""
    gens, rows = [], []
    with open(path) as f:
        reader = csv.reader(f)
        next(reader)
        for row in reader:
            if not row:
                continue
            gens.append(int(row[0]))
            rows.append([float(x) for x in row[1:]])
    return gens, rows


def stats(rows):
    mean, std, best = [], [], []
    for r in rows:
        finite = [x for x in r if x == x and abs(x) != float("inf")]
        n = len(finite)
        m = sum(finite) / n if n else float("nan")
        s = (sum((x - m) ** 2 for x in finite) / (n - 1)) ** 0.5 if n > 1 else 0.0
        mean.append(m)
        std.append(s)
        best.append(max(finite) if finite else float("nan"))
    return mean, std, best


def draw(ax, gens, rows, colour, label):
    mean, std, best = stats(rows)
    ax.fill_between(gens, [m - s for m, s in zip(mean, std)], [m + s for m, s in zip(mean, std)],
                    color=colour, alpha=0.2, linewidth=0)
    ax.plot(gens, mean, color=colour, label=f"{label} mean $\\pm$ std")
    ax.plot(gens, best, color=colour, linestyle="--", label=f"{label} max")


def main():
    summary_path, out_dir = sys.argv[1], sys.argv[2]
    with open(summary_path) as f:
        summary = json.load(f)
    by_experiment = {}
    for e in summary["experiments"]:
        by_experiment.setdefault(e["experiment"], []).append(e)
    names = list(by_experiment)
    overview, axes = plt.subplots(len(names), 2, figsize=(11, 3.4 * len(names)), squeeze=False)
    for row, name in enumerate(names):
        runs = by_experiment[name]
        single, single_axes = plt.subplots(1, 2, figsize=(11, 3.8))
        for panel_axes in (axes[row], single_axes):
            left, right = panel_axes
            for e in runs:
                gens, rows = read_history(e["csv"])
                draw(left, gens, rows, COLOURS.get(e["method"], "tab:green"),
                     f"{e['method']} ({e['climbers']} climbers)")
            left.set_title(f"{name}: {summary['fitness']} fitness, fidelity {summary['fidelity']}")
            voxel = runs[0].get("voxel_csv", "")
            if voxel and os.path.exists(voxel):
                gens, rows = read_history(voxel)
                draw(right, gens, rows, "tab:gray", f"voxel study ({len(rows[0])} climbers)")
                right.axvline(runs[0]["generations"], color="k", linewidth=0.8, linestyle=":")
                right.set_title(f"{name}: voxel study (dotted: this run's last generation)")
            else:
                right.text(0.5, 0.5, "no voxel-study run for this experiment", ha="center", va="center",
                           transform=right.transAxes)
                right.set_title(f"{name}: voxel study")
            for ax in panel_axes:
                ax.set_xlabel("generation")
                ax.set_ylabel("best speed so far [BL/s]")
                ax.grid(alpha=0.3)
                if ax.lines:
                    ax.legend(fontsize=7, loc="lower right")
        single.tight_layout()
        single.savefig(os.path.join(out_dir, f"curves_{name}.png"), dpi=110)
        plt.close(single)
    overview.tight_layout()
    overview.savefig(os.path.join(out_dir, "curves.png"), dpi=90)
    print(f"plots: {out_dir}/curves.png and curves_<experiment>.png", file=sys.stderr)


if __name__ == "__main__":
    main()
