#!/usr/bin/env python3
"""Check morphfem XDMF result files against their HDF5 data.

Usage: check_xdmf.py RESULT.xdmf [MORE.xdmf ...]

For every <DataItem Format="HDF"> the referenced file and dataset must exist,
with the declared dimensions, number type and precision; every dataset under
/mesh and /steps must be referenced; Time values must be finite and strictly
increasing; fields must be finite; cell node indices must be in range.
Prints one line per problem and exits 1, or prints nothing and exits 0.
Needs h5py (and numpy).
"""
import math
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np


def check(xdmf_path):
    problems = []
    root = ET.parse(xdmf_path).getroot()
    if root.tag != "Xdmf":
        return [f"{xdmf_path}: root element is {root.tag}, not Xdmf"]
    base = os.path.dirname(os.path.abspath(xdmf_path))
    times = [float(t.get("Value")) for t in root.iter("Time")]
    if any(not math.isfinite(t) for t in times):
        problems.append(f"{xdmf_path}: non-finite time")
    if any(b <= a for a, b in zip(times, times[1:])):
        problems.append(f"{xdmf_path}: times not strictly increasing: {times}")
    uniform = [g for g in root.iter("Grid") if g.get("GridType", "Uniform") == "Uniform"]
    if len(times) not in (0, len(uniform)):
        problems.append(f"{xdmf_path}: {len(times)} times for {len(uniform)} grids")

    files = {}
    referenced = {}
    try:
        for grid in uniform:
            topo = grid.find("Topology")
            geom = grid.find("Geometry")
            if topo is None or geom is None:
                problems.append(f"{xdmf_path}: grid {grid.get('Name')} lacks Topology or Geometry")
                continue
            n_nodes = None
            for owner in [geom, topo] + grid.findall("Attribute"):
                for item in owner.iter("DataItem"):
                    if item.get("Format") != "HDF":
                        problems.append(f"{xdmf_path}: DataItem not in HDF format")
                        continue
                    fname, _, dpath = item.text.strip().partition(":")
                    full = os.path.join(base, fname)
                    if full not in files:
                        if not os.path.exists(full):
                            problems.append(f"{xdmf_path}: missing file {fname}")
                            continue
                        files[full] = h5py.File(full, "r")
                    h5 = files[full]
                    referenced.setdefault(full, set()).add(dpath)
                    if dpath not in h5:
                        problems.append(f"{fname}: missing dataset {dpath}")
                        continue
                    ds = h5[dpath]
                    dims = tuple(int(x) for x in item.get("Dimensions").split())
                    if ds.shape != dims:
                        problems.append(f"{fname}:{dpath}: shape {ds.shape}, XDMF says {dims}")
                    kind = {"Float": "f", "Int": "i", "UInt": "u"}.get(item.get("NumberType", "Float"))
                    if ds.dtype.kind != kind or ds.dtype.itemsize != int(item.get("Precision", "4")):
                        problems.append(f"{fname}:{dpath}: dtype {ds.dtype} does not match XDMF")
                    data = ds[()]
                    if ds.dtype.kind == "f" and not np.all(np.isfinite(data)):
                        problems.append(f"{fname}:{dpath}: non-finite values")
                    if owner is geom:
                        n_nodes = ds.shape[0]
                    if owner is topo and n_nodes is not None and data.size:
                        if data.min() < 0 or data.max() >= n_nodes:
                            problems.append(f"{fname}:{dpath}: node index out of range")
                        npe = int(topo.get("NodesPerElement", ds.shape[-1]))
                        if ds.shape[-1] != npe or int(topo.get("NumberOfElements", ds.shape[0])) != ds.shape[0]:
                            problems.append(f"{fname}:{dpath}: topology size mismatch")
        for full, h5 in files.items():
            names = []
            h5.visititems(lambda n, o: names.append("/" + n) if isinstance(o, h5py.Dataset) else None)
            for n in names:
                if (n.startswith("/mesh/") or n.startswith("/steps/")) and n not in referenced[full]:
                    problems.append(f"{os.path.basename(full)}:{n}: not referenced by {xdmf_path}")
    finally:
        for h5 in files.values():
            h5.close()
    return problems


def main(argv):
    if len(argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    problems = []
    for path in argv[1:]:
        problems += check(path)
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
