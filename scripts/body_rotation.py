#!/usr/bin/env python3
"""Rotation of a robot body about its long (y) axis from a run's results.

Prints, per saved step, the centroid (x, z) and the angle of the seam-to-seam
vector of the mid-length cross-section (the nodes within 6 cm of mid-length and
1.1 cm of either long edge x = min / max in the reference): 0 deg when the body
lies flat, negative when it has rolled towards +x. Used to tell rolling from
rocking in the roll_flat diagnostics (docs/validation.md).

With --chambers it prints instead, per step, where each chamber (the volume regions
named bladder_K, from the result's region names) is: its angle about the centroid of
the mid-length band (0 = straight down, + towards +x) and the lowest point of its band
above the ground [mm]; the lowest point of each end of the body (the first and last
2.1 cm along y) [mm] and the ground's force on it [N]; and the whole ground force [N]. A push advances the rolling wave only if its chamber starts
behind the contact (negative angle) and ends more than 45 deg behind it.

    /usr/bin/python3 scripts/body_rotation.py RESULTS/CASE.h5 [T_FROM T_TO] [--every N] [--chambers]
"""
import argparse
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from result_regions import bladder_regions


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("window", nargs="*", type=float, help="optional time window [s]: from to")
    parser.add_argument("--every", type=int, default=3, help="print every N-th step outside a window")
    parser.add_argument("--chambers", action="store_true", help="each chamber's angle and height, and the ends' height")
    parser.add_argument("--bladder-regions", help="region ids of bladders 1..K, comma-separated, for results "
                        "written before region names were stored (e.g. 1,2,3,4,5,6,7,8 for the 3D physical preset)")
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
    if args.chambers:
        chambers(args, f, X, steps, times)
        return
    mid = np.abs(y - 0.5 * (y.min() + y.max())) < 0.06
    left = mid & (X[:, 0] < X[:, 0].min() + 0.011)
    right = mid & (X[:, 0] > X[:, 0].max() - 0.011)
    print("    t [s]   centroid x [m]  centroid z [m]  seam angle [deg]  seam distance [m]")
    for t, x in shown_steps(args, f, X, steps, times):
        v = x[right].mean(0) - x[left].mean(0)
        angle = np.degrees(np.arctan2(v[2], v[0]))
        print(f"{t:9.2f}  {x[:, 0].mean():15.3f} {x[:, 2].mean():15.3f}  {angle:16.1f}  {np.linalg.norm(v):17.3f}")


def shown_steps(args, f, X, steps, times):
    """(t, deformed coordinates) of each step in the window, or of every N-th step."""
    for i, step in enumerate(steps):
        t = times[i]
        if args.window[0] <= t <= args.window[1] if args.window else i % args.every == 0:
            yield t, X + f["/steps/" + step + "/displacement"][:]


def force_z(f, step):
    """Vertical ground contact force per node [N] (zeros if the step has none)."""
    path = "/steps/" + step + "/contact_force_N"
    if path not in f:
        return np.zeros(f["/mesh/X"].shape[0])
    force = f[path][:]
    return force[:, 2] if force.ndim == 2 else force


def chambers(args, f, X, steps, times):
    """Per step: each chamber's angle and lowest point, and the lowest point of each end."""
    region = f["/mesh/cell_region"]
    ids = bladder_regions("body_rotation.py", args.h5, region, args.bladder_regions)
    cells, cell_region = f["/mesh/cells"][:], region[:]
    y = X[:, 1]
    band = np.abs(y - 0.5 * (y.min() + y.max())) < min(0.02, 0.5 * (y.max() - y.min()) + 1e-12)
    nodes = {}
    for k, rid in ids:
        n = np.unique(cells[cell_region == rid].ravel())
        nodes[k] = n[band[n]]
    end_a, end_b = y < y.min() + 0.021, y > y.max() - 0.021
    header = " ".join(f"  chamber {k}" for k, _ in ids)
    print(f"    t [s]  {header}        end a       end b   ground force [N]"
          "   (chamber: angle [deg] / lowest [mm]; ends: lowest [mm] / ground force [N])")
    t_step = dict(zip(times, steps))
    for t, x in shown_steps(args, f, X, steps, times):
        centre = x[band].mean(0)
        cols = []
        for k, _ in ids:
            p = x[nodes[k]]
            m = p.mean(0) - centre
            cols.append(f"{np.degrees(np.arctan2(m[0], -m[2])):5.0f}/{1000 * p[:, 2].min():5.1f}")
        fz = force_z(f, t_step[t])
        ends = " ".join(f"{1000 * x[e, 2].min():5.1f}/{fz[e].sum():5.2f}" for e in (end_a, end_b))
        print(f"{t:9.2f}  " + " ".join(f"{c:>11}" for c in cols) + f"  {ends:>23}  {fz.sum():8.2f}")


if __name__ == "__main__":
    main()
