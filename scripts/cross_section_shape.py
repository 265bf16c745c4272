#!/usr/bin/env python3
"""Width / thickness of a robot's skin at mid-length from a run's results.

Takes the nodes of the skin cells (region id 0, the first volume of both robot
presets) within 1.1 cm of mid-length, at the saved step nearest to time T, and
prints their extent across (x) and up (z) and the ratio: how round the inflated
body is (1: a cylinder). Used for the voxel rolling slice table in the README.

    /usr/bin/python3 scripts/cross_section_shape.py RESULTS/CASE.h5 T [--region ID]
"""
import argparse
import sys

import numpy as np

from morphfem_result import open_result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("time", type=float, help="time [s]; the nearest saved step is used")
    parser.add_argument("--region", type=int, default=0, help="volume region id of the skin (default 0)")
    args = parser.parse_args()
    r = open_result(args.h5, "cross_section_shape.py")
    times, X, cells, region = r.times, r.X, r.cells, r.region
    if not (region == args.region).any():
        sys.exit(f"cross_section_shape.py: {args.h5}: no cells in region {args.region}")
    i = int(np.argmin([abs(t - args.time) for t in times]))
    x = r.deformed(i)
    skin = np.unique(cells[region == args.region][:, :4])
    y = X[:, 1]
    mid = np.where(np.abs(y - 0.5 * (y.min() + y.max())) < 0.011)[0]
    nodes = np.intersect1d(skin, mid)
    width, thickness = np.ptp(x[nodes, 0]), np.ptp(x[nodes, 2])
    print(f"t = {times[i]:.3f} s: width {100 * width:.2f} cm, thickness {100 * thickness:.2f} cm, "
          f"width/thickness {width / thickness:.3f}")


if __name__ == "__main__":
    main()
