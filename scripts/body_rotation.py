#!/usr/bin/env python3
"""Rotation of a robot body about its long (y) axis from a run's results.

Prints, per saved step, the centroid (x, z) and the angle of the seam-to-seam
vector of the mid-length cross-section (the nodes within 6 cm of mid-length and
1.1 cm of either long edge x = min / max in the reference): 0 deg when the body
lies flat, negative when it has rolled towards +x. Used to tell rolling from
rocking in the roll_flat diagnostics (README).

    /usr/bin/python3 scripts/body_rotation.py RESULTS/CASE.h5 [T_FROM T_TO] [--every N]
"""
import argparse
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("window", nargs="*", type=float, help="optional time window [s]: from to")
    parser.add_argument("--every", type=int, default=3, help="print every N-th step outside a window")
    args = parser.parse_args()
    if len(args.window) not in (0, 2):
        sys.exit("body_rotation.py: the time window needs two numbers (from to)")
    try:
        f = h5py.File(args.h5, "r")
        times = [float(t.get("Value")) for t in ET.parse(args.h5[:-3] + ".xdmf").iter("Time")]
        X = f["/mesh/X"][:]
        steps = sorted(f["/steps"].keys())
    except (OSError, KeyError, ET.ParseError) as e:
        sys.exit(f"body_rotation.py: {args.h5}: not a morphfem result ({e})")
    y = X[:, 1]
    mid = np.abs(y - 0.5 * (y.min() + y.max())) < 0.06
    left = mid & (X[:, 0] < X[:, 0].min() + 0.011)
    right = mid & (X[:, 0] > X[:, 0].max() - 0.011)
    print("    t [s]   centroid x [m]  centroid z [m]  seam angle [deg]  seam distance [m]")
    for i, step in enumerate(steps):
        t = times[i]
        shown = args.window[0] <= t <= args.window[1] if args.window else i % args.every == 0
        if not shown:
            continue
        x = X + f["/steps/" + step + "/displacement"][:]
        v = x[right].mean(0) - x[left].mean(0)
        angle = np.degrees(np.arctan2(v[2], v[0]))
        print(f"{t:9.2f}  {x[:, 0].mean():15.3f} {x[:, 2].mean():15.3f}  {angle:16.1f}  {np.linalg.norm(v):17.3f}")


if __name__ == "__main__":
    main()
