#!/usr/bin/env python3
"""How far a region's strains reach, against the range its material fit was made on.

usage: wall_stretch.py RESULTS.h5 [--region ID] [--every N] [--fit-strain E]

For each saved step: the largest and the 99th-percentile isochoric invariant
I1bar - 3 over the region's cells (I1bar = J^(-2/3) tr(F^T F), F of P1 or P2 cells
at four interior points), the largest principal stretch, the share of cells past
the fit's range, and, where the run has cavities, their pressures. A hyperelastic fit to a
uniaxial test up to engineering strain E has seen I1bar - 3 only up to
lam^2 + 2/lam - 3, lam = 1 + E (E = 2: 6.67); beyond it the law is an extrapolation
(the Yeoh presets' negative c3 softens them: dW/dI1 falls past I1bar - 3 = 8.4 for
Dragon Skin 30, fem/material.cpp). Region ids as in chamber_bulge.py (with
`fabric: membrane`, bladder_1..8 = 1..8; default 1).
"""
import argparse
import sys

import h5py
import numpy as np


# VTK node order of the quadratic tetrahedron (fem/element.h): vertices 0..3, then
# the edges (0,1) (1,2) (2,0) (0,3) (1,3) (2,3).
EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
DL = np.array([[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])  # dL_i/dxi


def reference_gradients(n, L):
    """dN/dxi (n x 3) of the P1 (n = 4) or P2 (n = 10) tetrahedron at barycentric L."""
    if n == 4:
        return DL.copy()
    g = np.zeros((10, 3))
    for i in range(4):
        g[i] = (4.0 * L[i] - 1.0) * DL[i]
    for e, (i, j) in enumerate(EDGES):
        g[4 + e] = 4.0 * (L[j] * DL[i] + L[i] * DL[j])
    return g


def invariants(X, x, cells):
    """I1bar - 3 and the largest principal stretch of each cell, the largest over
    four interior points (barycentric 0.585, 0.138, 0.138, 0.138 and permutations)."""
    n = cells.shape[1]
    i1 = np.full(len(cells), -np.inf)
    lam = np.zeros(len(cells))
    a, b = 0.5854101966249685, 0.1381966011250105
    for k in range(4):
        L = np.full(4, b)
        L[k] = a
        g = reference_gradients(n, L)  # (n, 3)
        Jx = np.einsum("cai,aj->cij", X[cells], g)  # dX/dxi (cells, 3, 3)
        jx = np.einsum("cai,aj->cij", x[cells], g)  # dx/dxi
        F = jx @ np.linalg.inv(Jx)
        C = np.einsum("nki,nkj->nij", F, F)
        J = np.linalg.det(F)
        i1 = np.maximum(i1, np.trace(C, axis1=1, axis2=2) * np.abs(J) ** (-2.0 / 3.0) - 3.0)
        lam = np.maximum(lam, np.sqrt(np.linalg.eigvalsh(C)[:, -1]))
    return i1, lam


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("h5")
    ap.add_argument("--region", type=int, default=1, help="volume region id (default 1: bladder_1 of a membrane body)")
    ap.add_argument("--every", type=int, default=1, help="every N-th saved step")
    ap.add_argument("--fit-strain", type=float, default=2.0, help="engineering strain the fit went to (default 2.0)")
    a = ap.parse_args()
    lam = 1.0 + a.fit_strain
    fit_i1 = lam * lam + 2.0 / lam - 3.0
    try:
        f = h5py.File(a.h5, "r")
    except OSError as e:
        sys.exit(f"{a.h5}: cannot read ({e})")
    with f:
        if "mesh/X" not in f or "steps" not in f:
            sys.exit(f"{a.h5}: not a morphfem result (no mesh/X or steps)")
        X = f["mesh/X"][:]
        cells = f["mesh/cells"][:]
        region = f["mesh/cell_region"][:]
        steps = sorted(f["steps"].keys())
        cav = None
        if "tables/cavities" in f:
            cav = f["tables/cavities"][:]
            cols = [c.decode() for c in f["tables/cavities"].attrs["columns"]]
        tets = cells[region == a.region]
        if len(tets) == 0:
            sys.exit(f"{a.h5}: no cells in region {a.region}")
        print(f"region {a.region}: {len(tets)} cells; uniaxial fit to strain {a.fit_strain:g} covers I1bar-3 <= {fit_i1:.2f}")
        pcols = [i for i, c in enumerate(cols) if c.endswith("_pressure_Pa")] if cav is not None else []
        head = f"{'t [s]':>8} {'max I1-3':>9} {'p99 I1-3':>9} {'max lam':>8} {'> fit':>7}"
        head += "".join(f" {cols[i][:-len('_pressure_Pa')] + ' [kPa]':>10}" for i in pcols)
        print(head)
        for s in steps[:: max(1, a.every)]:
            g = f["steps/" + s]
            t = g.attrs.get("time", float("nan"))
            i1, lm = invariants(X, X + g["displacement"][:], tets)
            row = f"{t:8.3f} {i1.max():9.3f} {np.percentile(i1, 99):9.3f} {lm.max():8.3f} {np.mean(i1 > fit_i1):7.1%}"
            if cav is not None and len(cav):
                k = int(np.argmin(np.abs(cav[:, 0] - t)))
                row += "".join(f" {cav[k, i] / 1e3:10.3f}" for i in pcols)
            print(row)


if __name__ == "__main__":
    main()
