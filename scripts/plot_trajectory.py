#!/usr/bin/env python3
"""Plot a gait run's centroid trajectory (trajectory.csv + summary.json of a result folder).

usage: plot_trajectory.py RESULT_DIR [OUT.png]

Top: the mean node position in the ground plane (x, y) [cm], start and end marked,
the heading as an arrow. Bottom: displacement along the heading and height of the
centroid against time [s], the gait interval shaded.
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(folder, "trajectory.png")
    data = np.loadtxt(os.path.join(folder, "trajectory.csv"), delimiter=",", skiprows=1, ndmin=2)
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    t, x, y, z = data[:, 0], data[:, 1], data[:, 2], data[:, 3]
    start = summary.get("gait_start_s", t[0])
    end = start + summary.get("simulated_gait_s", t[-1] - start)
    heading = summary.get("heading", None)
    if heading is None:
        # Fall back on the direction of travel over the gait.
        heading = [x[-1] - x[0], y[-1] - y[0]]
    h = np.array(heading[:2], dtype=float)
    h = h / (np.linalg.norm(h) or 1.0)
    i0 = int(np.argmin(np.abs(t - start)))
    along = (x - x[i0]) * h[0] + (y - y[i0]) * h[1]

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(6.4, 7.2))
    ax1.plot(100 * x, 100 * y, "-", lw=1.2)
    ax1.plot(100 * x[i0], 100 * y[i0], "go", label="gait start")
    ax1.plot(100 * x[-1], 100 * y[-1], "rs", label="end")
    span = max(np.ptp(100 * x), np.ptp(100 * y), 1.0)
    ax1.annotate("", xy=(100 * x[i0] + 0.3 * span * h[0], 100 * y[i0] + 0.3 * span * h[1]),
                 xytext=(100 * x[i0], 100 * y[i0]), arrowprops=dict(arrowstyle="->", color="k"))
    ax1.set_xlabel("x [cm]")
    ax1.set_ylabel("y [cm]")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.legend(loc="best", fontsize=8)
    speed = summary.get("speed_bl_per_s", float("nan"))
    ax1.set_title("%s: %+.4f BL/s, %+.1f mm along the heading" %
                  (summary.get("scene", ""), speed, 1000 * summary.get("displacement_m", math.nan)), fontsize=10)
    ax2.axvspan(start, end, color="0.92", label="gait")
    ax2.plot(t, 100 * along, label="along heading")
    ax2.plot(t, 100 * z, label="height")
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("centroid [cm]")
    ax2.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
