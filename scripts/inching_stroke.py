#!/usr/bin/env python3
"""Foot stroke, travel and belly sag of a flat inching robot from a run's results.

The feet are the nodes within `--foot` of either end (y) and within `--pad` of the
lowest plane (z) in the reference; the belly is the lowest nodes between the feet.
After `--start` (the end of settling) it prints
  * the distance between the feet's centroids: min, max and their difference, the
    stroke the chambers make each cycle (0 if the body cannot bend);
  * each foot's travel along y from `--start` to the last saved step;
  * the belly's lowest height over the run (the ground plane's height is the scene's
    contact point: a belly within the barrier width dhat of it is touching);
  * each foot's largest pull |F_y| / N over the saved steps after `--start` (friction
    force along the body over normal force, summed over the foot's nodes): a foot
    slides only when its pull reaches its friction coefficient.
With --steps it first prints, per saved step after `--start`, each foot's friction force
along y [N] and normal force [N] and the force on the rest of the body, so one sees which
foot anchors in which column.
Used for the physical inching ladder in docs/physical-robot.md, and (--foot 0.03 --pad 0.0041
--steps: the voxel preset's feet are the bottom skin layer's ends at z = 4 mm) for the
voxel preset's feet.

    /usr/bin/python3 scripts/inching_stroke.py RESULTS/CASE.h5 [--start 1.0] [--foot 0.02] [--pad 0.004] [--steps]
"""
import argparse
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("--start", type=float, default=1.0, help="end of settling [s] (default 1.0)")
    parser.add_argument("--foot", type=float, default=0.02, help="foot length along y [m] (default 0.02)")
    parser.add_argument("--pad", type=float, default=0.004, help="foot pad height [m] (default 0.004)")
    parser.add_argument("--steps", action="store_true", help="print each foot's forces per saved step")
    args = parser.parse_args()
    try:
        f = h5py.File(args.h5, "r")
        times = np.array([float(t.get("Value")) for t in ET.parse(args.h5[:-3] + ".xdmf").iter("Time")])
        X = f["/mesh/X"][:]
        steps = sorted(f["/steps"].keys())
    except (OSError, KeyError, ET.ParseError) as e:
        sys.exit(f"inching_stroke.py: {args.h5}: not a morphfem result ({e})")
    y, z = X[:, 1], X[:, 2]
    low = z <= z.min() + args.pad + 1e-9
    foot_a = low & (y <= y.min() + args.foot)
    foot_b = low & (y >= y.max() - args.foot)
    between = (y > y.min() + args.foot + 0.01) & (y < y.max() - args.foot - 0.01)
    if not (foot_a.any() and foot_b.any() and between.any()):
        sys.exit(f"inching_stroke.py: {args.h5}: no feet or belly found (check --foot and --pad)")
    belly = between & (z <= z[between].min() + 1e-9)
    later = times[: len(steps)] >= args.start
    if not later.any():
        sys.exit(f"inching_stroke.py: {args.h5}: no saved step after --start {args.start} s")
    distance, ya, yb, belly_z = [], [], [], []
    pull = {"A": 0.0, "B": 0.0}
    rest = ~(foot_a | foot_b)
    if args.steps:
        print("t [s]   foot A: F_y [N]  N [N]   foot B: F_y [N]  N [N]   rest: F_y [N]  N [N]")
    for k, s in enumerate(steps):
        g = f["/steps/" + s]
        if later[k] and "friction_force_N" in g and "contact_force_N" in g:
            normal, friction = g["contact_force_N"][:], g["friction_force_N"][:]
            for name, foot in (("A", foot_a), ("B", foot_b)):
                n = np.linalg.norm(normal[foot], axis=1).sum()
                if n > 0:
                    pull[name] = max(pull[name], abs(friction[foot, 1].sum()) / n)
            if args.steps:
                row = [f"{times[k]:6.2f}"]
                for part in (foot_a, foot_b, rest):
                    row.append(f"{friction[part, 1].sum():14.3f} {np.linalg.norm(normal[part], axis=1).sum():6.2f}")
                print("  ".join(row))
        x = X + f["/steps/" + s + "/displacement"][:]
        ya.append(x[foot_a, 1].mean())
        yb.append(x[foot_b, 1].mean())
        distance.append(yb[-1] - ya[-1])
        belly_z.append(x[belly, 2].min())
    distance = np.array(distance)[later]
    first = int(np.argmax(later))
    print(f"feet distance {1e3 * distance.min():.2f} .. {1e3 * distance.max():.2f} mm: stroke "
          f"{1e3 * (distance.max() - distance.min()):.3f} mm; travel foot A {1e3 * (ya[-1] - ya[first]):.2f} mm, "
          f"foot B {1e3 * (yb[-1] - yb[first]):.2f} mm; belly lowest at z = {1e3 * min(belly_z):.3f} mm "
          f"(reference {1e3 * z[belly].min():.3f} mm); largest pull |F_y|/N foot A {pull['A']:.3f}, "
          f"foot B {pull['B']:.3f}")


if __name__ == "__main__":
    main()
