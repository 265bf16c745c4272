#!/usr/bin/env python3
"""Plots for `morphfem calibrate` (called by the program when /usr/bin/python3 exists).

usage: plot_calibration.py pull      pull_tests.csv        out.png   # box plot per surface / foot state
       plot_calibration.py friction  friction_overlay.csv  out.png   # data curves and the fitted simulation
       plot_calibration.py materials material_fit_curves.csv out.png # tensile data and fitted laws
       plot_calibration.py curves    friction_drag_curves.csv out.png # simulated pull curves (robot friction-drag)
"""
import csv
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def plot_pull(rows, png):
    groups = OrderedDict()
    for r in rows:
        groups.setdefault(f"{r['surface']}\n{r['foot_state']}", []).append(r)
    names = list(groups)
    fig, axes = plt.subplots(1, 3, figsize=(12, 4), sharey=True)
    for ax, key, title in zip(axes, ["mu_linear", "mu_peak", "mu_kinetic"],
                              ["static (end of linear regime)", "static peak (ASTM D1894)", "kinetic (ASTM D1894)"]):
        ax.boxplot([[float(r[key]) for r in groups[n]] for n in names], labels=names)
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("friction coefficient [-]")
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def read_curves(rows):
    """Rows (curve, displacement_mm, force_N) -> {curve: (x [mm], F [N])} in file order."""
    curves = OrderedDict()
    for r in rows:
        curves.setdefault(r["curve"], ([], []))
        curves[r["curve"]][0].append(float(r["displacement_mm"]))
        curves[r["curve"]][1].append(float(r["force_N"]))
    return curves


def finish_pull_axes(axes, png, legend_size):
    """Labels, grid and legend of force-travel axes; saves the figure."""
    for a in axes:
        a.set_xlabel("crosshead travel [mm]")
        a.set_ylabel("pull force [N]")
        a.grid(alpha=0.3)
        a.legend(fontsize=legend_size)
    axes[0].figure.tight_layout()
    axes[0].figure.savefig(png, dpi=120)


def plot_friction(rows, png):
    curves = read_curves(rows)
    _, ax = plt.subplots(figsize=(7, 4.5))
    for name, (x, f) in curves.items():
        if name == "simulated":
            continue
        ax.plot(x, f, ".", ms=2, alpha=0.5, label=name)
    if "simulated" in curves:
        x, f = curves["simulated"]
        ax.plot(x, f, "k-", lw=1.5, label="simulated (fitted)")
    finish_pull_axes([ax], png, 7)


def plot_curves(rows, png):
    curves = read_curves(rows)
    _, (ax, zoom) = plt.subplots(1, 2, figsize=(11, 4.5))
    for name, (x, f) in curves.items():
        for a in (ax, zoom):
            a.plot(x, f, "-", lw=1.2, label=name)
    zoom.set_xlim(0, min(10.0, max(max(x) for x, _ in curves.values())))
    ax.set_title("load against extension")
    zoom.set_title("pre-slip rise and static peak")
    finish_pull_axes([ax, zoom], png, 8)


def plot_materials(rows, png):
    materials = OrderedDict()
    for r in rows:
        materials.setdefault(r["material"], []).append(r)
    fig, axes = plt.subplots(1, len(materials), figsize=(6 * len(materials), 4.5), squeeze=False)
    models = ["neo_hookean_pa", "yeoh_pa", "ogden1_pa", "ogden2_pa", "ogden3_pa"]
    for ax, (name, rs) in zip(axes[0], materials.items()):
        strain = [float(r["stretch"]) - 1 for r in rs]
        ax.plot(strain, [float(r["data_nominal_stress_pa"]) / 1e3 for r in rs], "k.", ms=3, label="data")
        for m in models:
            ax.plot(strain, [float(r[m]) / 1e3 for r in rs], "-", lw=1, label=m.replace("_pa", ""))
        ax.set_title(name)
        ax.set_xlabel("engineering strain [-]")
        ax.set_ylabel("nominal stress [kPa]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("pull", "friction", "materials", "curves"):
        print(__doc__, file=sys.stderr)
        return 2
    rows = read_rows(sys.argv[2])
    {"pull": plot_pull, "friction": plot_friction, "materials": plot_materials, "curves": plot_curves}[sys.argv[1]](rows, sys.argv[3])
    return 0


if __name__ == "__main__":
    sys.exit(main())
