#!/usr/bin/env python3
"""How far a flat robot bends along its length (y) from a run's results: curl angle and side views.

Takes the skin nodes (volume region 0, as in cross_section_shape.py) within --band of
mid-width (x) in the reference, cuts them into --bins slices along the reference y,
and follows each slice's deformed centroid (y, z). The curl is the angle the line
through successive centroids turns from the first slice to the last, unwrapped:
0 deg flat, 180 deg a U, 360 deg a closed ring;
negative when the body arches (middle up, ends down), positive when it sags. It is the
turn between the first and the last segment, so it reads (bins - 1) / bins of a uniform
arc's end-to-end turn (-164 deg for a half circle with 11 bins). Per saved step from --start to --end it prints
t, the curl [deg], the highest skin point [mm] and the distance between the end slices
[mm]; then the largest curl. With --png FILE it also draws the side views (y against z;
skin and the other regions in two colours) at the --at times (nearest saved steps).
Used for the inching P2 check in docs/validation.md (the lattice's growth curls a
non-locking body into a ring).

    /usr/bin/python3 scripts/side_profile.py RESULTS/CASE.h5 [--start 1.5] [--end T] [--every 1]
        [--band 0.012] [--bins 11] [--png FILE --at T1 T2 ...]
"""
import argparse
import sys

import numpy as np

from morphfem_result import open_result


def curl_deg(points):
    """Unwrapped turn [deg] of the polyline through `points` ((n, 2): y, z), first to last segment."""
    d = np.diff(points, axis=0)
    angle = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    return np.degrees(angle[-1] - angle[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("--start", type=float, default=0.0, help="first time to print [s] (default 0)")
    parser.add_argument("--end", type=float, default=float("inf"), help="last time to print [s] (default: all)")
    parser.add_argument("--every", type=int, default=1, help="print every N-th saved step (default 1)")
    parser.add_argument("--band", type=float, default=0.012, help="half-width of the mid-width band [m]")
    parser.add_argument("--bins", type=int, default=11, help="slices along y (default 11)")
    parser.add_argument("--png", help="write side views to this PNG file")
    parser.add_argument("--at", type=float, nargs="*", default=[], help="times of the side views [s]")
    args = parser.parse_args()
    if args.bins < 3 or args.every < 1:
        sys.exit("side_profile.py: --bins must be at least 3 and --every at least 1")
    if args.png and not args.at:
        sys.exit("side_profile.py: --png needs the times of the views (--at T1 T2 ...)")
    r = open_result(args.h5, "side_profile.py")
    times, X, cells, region, steps = r.times, r.X, r.cells, r.region, r.steps
    skin = np.zeros(len(X), bool)
    skin[np.unique(cells[region == 0])] = True
    x_mid = 0.5 * (X[:, 0].min() + X[:, 0].max())
    band = skin & (np.abs(X[:, 0] - x_mid) < args.band)
    edges = np.linspace(X[:, 1].min(), X[:, 1].max(), args.bins + 1)
    slices = [band & (X[:, 1] >= lo) & (X[:, 1] <= hi) for lo, hi in zip(edges[:-1], edges[1:])]
    if any(not s.any() for s in slices):
        sys.exit(f"side_profile.py: {args.h5}: a slice has no skin node; use fewer --bins or a wider --band")

    print("t [s]   curl [deg]   top z [mm]   end-to-end [mm]")
    largest = (0.0, 0.0)
    for k in range(len(steps)):
        if times[k] < args.start or times[k] > args.end:
            continue
        x = r.deformed(k)
        centres = np.array([x[s][:, 1:].mean(axis=0) for s in slices])
        curl = curl_deg(centres)
        if abs(curl) > abs(largest[0]):
            largest = (curl, times[k])
        if k % args.every == 0:
            print(f"{times[k]:6.3f}  {curl:10.1f}  {1e3 * x[skin, 2].max():11.1f}  "
                  f"{1e3 * np.linalg.norm(centres[-1] - centres[0]):15.1f}")
    print(f"largest curl {largest[0]:.1f} deg at t = {largest[1]:.3f} s")

    if args.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        mid = np.abs(X[:, 0] - x_mid) < args.band
        other = np.zeros(len(X), bool)
        other[np.unique(cells[region != 0])] = True
        fig, axes = plt.subplots(1, len(args.at), figsize=(4 * len(args.at), 3.6), squeeze=False)
        for ax, t in zip(axes[0], args.at):
            k = int(np.argmin(np.abs(times - t)))
            x = r.deformed(k)
            for part, colour, name in ((mid & skin, "tab:blue", "skin"), (mid & other & ~skin, "tab:orange", "other")):
                ax.scatter(1e3 * x[part, 1], 1e3 * x[part, 2], s=2, c=colour, label=name)
            centres = np.array([x[s][:, 1:].mean(axis=0) for s in slices])
            ax.set_title(f"t = {times[k]:.2f} s, curl {curl_deg(centres):.0f} deg")
            ax.set_xlabel("y [mm]")
            ax.set_ylabel("z [mm]")
            ax.set_aspect("equal")
            ax.axhline(0.0, color="k", lw=0.5)
        axes[0][0].legend(loc="upper left", fontsize=7)
        fig.tight_layout()
        fig.savefig(args.png, dpi=100)
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
