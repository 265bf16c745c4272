#!/usr/bin/env python3
"""Inching speed against the feet's mean friction: finite elements beside the voxel study.

usage: plot_friction_sweep.py friction_sweep.json sfrict_results.csv [OUT.png]
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        sweep = json.load(f)
    voxel = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, ndmin=2)
    out = sys.argv[3] if len(sys.argv) > 3 else os.path.join(os.path.dirname(sys.argv[1]), "friction_sweep.png")
    pts = [p for p in sweep["points"] if p["completed"]]
    mean = [(p["mu_low"] + p["mu_high"]) / 2 for p in pts]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot((voxel[:, 0] + voxel[:, 1]) / 2, voxel[:, 4], "o", color="0.4", label="voxel study (sfrict_results.csv)")
    ax.plot(mean, [p["speed_bl_per_s"] for p in pts], "s-", label="finite elements, level %s" % sweep["fidelity"])
    ax.axhline(0, color="0.8", lw=0.8)
    ax.set_xlabel("mean foot friction (active - inactive = 2.0)")
    ax.set_ylabel("inching speed [BL/s]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
