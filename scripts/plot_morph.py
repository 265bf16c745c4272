#!/usr/bin/env python3
"""Width/thickness of the robot against core pressure (morph.csv of `morphfem robot morph`).

usage: plot_morph.py morph.csv [OUT.png]
Left: width and thickness [cm] against time with the core pressure; right:
width/thickness against core pressure (inflation and deflation branches).
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(path), "morph.png")
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    t, p, w, h, ratio = d[:, 0], d[:, 1], d[:, 2], d[:, 4], d[:, 5]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(t, 100 * w, label="width (x)")
    a1.plot(t, 100 * h, label="thickness (z)")
    a1.set_xlabel("t [s]")
    a1.set_ylabel("[cm]")
    a3 = a1.twinx()
    a3.plot(t, p / 1000, "k--", lw=0.8, label="core pressure")
    a3.set_ylabel("core pressure [kPa]")
    a1.legend(loc="upper left", fontsize=8)
    peak = int(np.argmax(p))
    a2.plot(p[: peak + 1] / 1000, ratio[: peak + 1], "o-", ms=3, label="inflating")
    a2.plot(p[peak:] / 1000, ratio[peak:], "s-", ms=3, label="deflating")
    a2.axhspan(0.8, 1.25, color="0.9", label="cylinder [0.8, 1.25]")
    a2.axhline(6, color="0.6", ls=":", label="flat >= 6")
    a2.set_xlabel("core pressure [kPa]")
    a2.set_ylabel("width / thickness")
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
