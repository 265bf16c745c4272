#!/usr/bin/env python3
"""Bulge of an outer chamber of the round physical body, from a run's results.

usage: chamber_bulge.py RESULTS.h5 [--region ID] [--radius R] [--time T] [--band B]

h = (largest distance of the chamber's nodes from the body's axis) - (skin's outer
radius), at the last output step (or the saved step nearest T), in the x-z
cross-section; for a 3D body, --band B takes only the nodes within B of the mesh's
mid-length (y); theta = acos(R / (R + h))
is how far a rigid cylinder of radius R turns when lifted by that bump at its contact.
A push of the rolling schedule advances the wave only if theta > 45 deg (h > 0.41 R;
docs/physical-robot.md, "Rolling"). The axis is the mean of the skin nodes.
Region ids follow the mesh's volume order: robot_physical has skin 0, fabric 1,
bladder_1..8 = 2..9 (default 9: bladder_8, the first chamber of the rolling schedule);
with `fabric: membrane` there is no fabric volume and bladder_8 is 8.
"""
import argparse
import math

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("h5")
    ap.add_argument("--region", type=int, default=9, help="volume region id of the chamber (default 9)")
    ap.add_argument("--radius", type=float, default=None, help="R for theta [m] (default: the skin's outer radius)")
    ap.add_argument("--time", type=float, default=None, help="time [s]: the saved step nearest it (default: the last)")
    ap.add_argument("--band", type=float, default=None, help="half-width [m] of a band around mid-length (3D bodies)")
    a = ap.parse_args()
    with h5py.File(a.h5, "r") as f:
        X = f["mesh/X"][:]
        cells = f["mesh/cells"][:]
        region = f["mesh/cell_region"][:]
        steps = sorted(f["steps"].keys())
        times = np.array([f["steps/" + k].attrs.get("time", float("nan")) for k in steps])
        step = steps[-1] if a.time is None else steps[int(np.nanargmin(np.abs(times - a.time)))]
        x = X + f["steps/" + step + "/displacement"][:]
        t = f["steps/" + step].attrs.get("time", float("nan"))
    if not np.any(region == a.region):
        raise SystemExit(f"{a.h5}: no cells in region {a.region}")
    chamber = np.unique(cells[region == a.region].ravel())
    skin = np.unique(cells[region == 0].ravel())
    if a.band is not None:
        mid = 0.5 * (X[:, 1].min() + X[:, 1].max())
        chamber = chamber[np.abs(X[chamber, 1] - mid) <= a.band]
        skin = skin[np.abs(X[skin, 1] - mid) <= a.band]
        if len(chamber) == 0 or len(skin) == 0:
            raise SystemExit(f"{a.h5}: no chamber or skin nodes within {a.band} m of mid-length")
    axis = x[skin][:, [0, 2]].mean(axis=0)
    r_skin = np.linalg.norm(x[skin][:, [0, 2]] - axis, axis=1).max()
    r_chamber = np.linalg.norm(x[chamber][:, [0, 2]] - axis, axis=1).max()
    R = a.radius if a.radius else r_skin
    h = r_chamber - r_skin
    theta = math.degrees(math.acos(R / (R + h))) if h > 0 else 0.0
    print(f"t = {t:.3f} s: skin outer radius {100 * r_skin:.2f} cm, chamber reaches {100 * r_chamber:.2f} cm, "
          f"bulge h {100 * h:.2f} cm, theta {theta:.1f} deg (a push advances if > 45 deg, h > {100 * 0.41 * R:.2f} cm)")


if __name__ == "__main__":
    main()
