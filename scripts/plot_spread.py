#!/usr/bin/env python3
"""A perturbation ensemble of one robot case (morphfem robot spread): every run's speed per
fidelity level, with the level's mean +- one sample standard deviation and its median.

usage: plot_spread.py CASE_spread.json [--png OUT.png]   (default: CASE_spread.png beside the JSON)
"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("summary", help="CASE_spread.json written by morphfem robot spread")
    parser.add_argument("--png", help="output PNG (default: beside the JSON)")
    args = parser.parse_args()
    with open(args.summary) as f:
        spread = json.load(f)
    out = args.png or os.path.splitext(args.summary)[0] + ".png"
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    names = []
    for i, level in enumerate(spread["levels"]):
        names.append("%s\n%.3g m P%d" % (level["level"], level["mesh_size_m"], level["order"])
                     if spread["preset"] == "voxel" else level["level"])
        ok = [r for r in level["runs"] if r["completed"]]
        bad = [r for r in level["runs"] if not r["completed"]]
        ax.plot([i] * len(ok), [r["speed_bl_per_s"] for r in ok], "o", color="C0", alpha=0.7,
                label="one run" if i == 0 else None)
        ax.plot([i] * len(bad), [r["speed_bl_per_s"] for r in bad], "x", color="C3",
                label="failed run" if bad and i == 0 else None)
        if level["mean_bl_per_s"] is not None:
            std = level["std_bl_per_s"] or 0.0
            ax.errorbar(i + 0.15, level["mean_bl_per_s"], yerr=std, fmt="s", color="C1", capsize=4,
                        label="mean +- std" if i == 0 else None)
        if level.get("median_bl_per_s") is not None:
            ax.plot(i + 0.15, level["median_bl_per_s"], "_", color="C2", ms=16, mew=2,
                    label="median" if i == 0 else None)
        voxel = level["runs"][0].get("voxel_bl_per_s") if level["runs"] else None
    if voxel is not None:
        ax.axhline(voxel, color="0.4", ls="--", lw=1, label="voxel study")
    ax.axhline(0, color="0.8", lw=0.8)
    ax.set_xlim(-0.5, len(names) - 0.5)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names)
    ax.set_xlabel("fidelity level")
    ax.set_ylabel("speed [BL/s]")
    ax.set_title("%s: %s varied" % (spread["case"], spread["varied_key"]), fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
