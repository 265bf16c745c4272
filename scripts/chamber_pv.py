#!/usr/bin/env python3
"""Pressure-volume curves of a run's cavities, from its HDF5 `tables/cavities`.

    /usr/bin/python3 scripts/chamber_pv.py RESULT.h5 [--cavity b1] [--png OUT.png] [--every N]

Prints, per cavity, time, V/V_ref (V_ref the first row's volume), gauge pressure
[kPa], and the largest pressure with its volume ratio, called a pressure maximum
when the chamber later holds more volume at a lower pressure (pressure control has
no nearby equilibrium past it). Writes a PNG of pressure against V/V_ref.
"""
import argparse
import sys

import h5py
import numpy as np


def read_cavities(path):
    try:
        with h5py.File(path, "r") as f:
            if "tables/cavities" not in f:
                sys.exit(f"{path}: no tables/cavities (the scene has no cavities)")
            table = f["tables/cavities"][:]
            columns = [c.decode() for c in f["tables/cavities"].attrs["columns"]]
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e})")
    names = [c[: -len("_pressure_Pa")] for c in columns if c.endswith("_pressure_Pa")]
    out = {}
    for n in names:
        p = table[:, columns.index(n + "_pressure_Pa")]
        v = table[:, columns.index(n + "_volume_m3")]
        out[n] = (table[:, 0], v, p)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("h5")
    ap.add_argument("--cavity", action="append", help="cavity name (default: every cavity)")
    ap.add_argument("--png", help="PNG of p against V/V_ref")
    ap.add_argument("--every", type=int, default=1, help="print every N-th row")
    a = ap.parse_args()
    curves = read_cavities(a.h5)
    names = a.cavity or list(curves)
    for n in names:
        if n not in curves:
            sys.exit(f"{a.h5}: no cavity '{n}' (have: {', '.join(curves)})")
    for n in names:
        t, v, p = curves[n]
        ratio = v / v[0]
        print(f"cavity {n}: V_ref {v[0]:.4e} m^3")
        print(f"{'t [s]':>8} {'V/V_ref':>8} {'p [kPa]':>9}")
        for i in range(0, len(t), max(1, a.every)):
            print(f"{t[i]:8.3f} {ratio[i]:8.3f} {p[i] / 1e3:9.3f}")
        k = int(np.argmax(p))
        # A pressure maximum of the wall: later states hold more volume at a lower
        # pressure (a setpoint plateau or a deflation is not one).
        later = (ratio[k + 1 :] > ratio[k]) & (p[k + 1 :] < 0.99 * p[k])
        where = "a pressure maximum: the chamber grows past it at falling pressure" if later.any() else "not a maximum"
        print(f"largest pressure {p[k] / 1e3:.3f} kPa at V/V_ref {ratio[k]:.3f} (t = {t[k]:.3f} s), {where}")
    if a.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.6))
        for n in names:
            t, v, p = curves[n]
            ax.plot(v / v[0], p / 1e3, ".-", ms=3, label=n)
        ax.set_xlabel("V / V_ref")
        ax.set_ylabel("gauge pressure [kPa]")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.png, dpi=150)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
