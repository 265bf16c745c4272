#!/usr/bin/env python3
"""Timoshenko's bimorph estimate of how far the voxel preset's growth bends the flat body.

Two bonded layers: the skin (thickness t1, modulus E1) and the layer of top bladders
(t2, E2) that grows along the body by the strain mismatch eps. Timoshenko (1925,
"Analysis of bi-metal thermostats") gives the curvature

    kappa = 6 eps (1 + m)^2 / (h (3 (1 + m)^2 + (1 + m n) (m^2 + 1 / (m n))))

with m = t1 / t2, n = E1 / E2, h = t1 + t2. The turn over the bladders' length L is
L kappa. Small-strain formula: an order-of-magnitude check of the finite-element arch
(scripts/side_profile.py), not a prediction of it.

Defaults are the voxel preset's: 1 cm skin, 2.5 cm inflated bladder layer, eps = 1.35
(the lattice's along-y growth at 0 kPa, s_y = 2.35; actuation/voxel_growth.h), 15 cm of
bladders, and bladders E/1.8 (face-contact preset) or 12.5x that (lattice-mechanics).

    /usr/bin/python3 scripts/bimorph_curl.py [--eps 1.35] [--skin 0.01] [--bladder 0.025]
        [--length 0.15] [--ratio 1.8] [--stiffer 1 12.5]
"""
import argparse
import math


def curvature(eps, t1, t2, n):
    """Timoshenko's bimorph curvature [1/m] for thicknesses t1, t2 [m] and modulus ratio n = E1/E2."""
    m = t1 / t2
    h = t1 + t2
    return 6 * eps * (1 + m) ** 2 / (h * (3 * (1 + m) ** 2 + (1 + m * n) * (m * m + 1 / (m * n))))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--eps", type=float, default=1.35, help="growth strain mismatch (default 1.35)")
    p.add_argument("--skin", type=float, default=0.01, help="skin thickness [m] (default 0.01)")
    p.add_argument("--bladder", type=float, default=0.025, help="bladder layer thickness [m] (default 0.025)")
    p.add_argument("--length", type=float, default=0.15, help="length of the bladders [m] (default 0.15)")
    p.add_argument("--ratio", type=float, default=1.8, help="skin modulus / bladder modulus (default 1.8)")
    p.add_argument("--stiffer", type=float, nargs="+", default=[1.0, 12.5],
                   help="bladder stiffening factors to tabulate (default 1 12.5)")
    a = p.parse_args()
    print("bladders stiffer by   E_skin/E_bladder   radius [cm]   turn over the bladders [deg]")
    for f in a.stiffer:
        n = a.ratio / f
        kappa = curvature(a.eps, a.skin, a.bladder, n)
        print(f"{f:20.4g}   {n:16.4g}   {100 / kappa:11.2f}   {math.degrees(a.length * kappa):28.0f}")


if __name__ == "__main__":
    main()
