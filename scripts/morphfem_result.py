"""Reads a morphfem run's results (the HDF5 file and the XDMF beside it) for the analysis scripts.

    from morphfem_result import open_result
    r = open_result("RESULTS/CASE.h5", "my_script.py")  # exits with a message if it is not a result
    r.times, r.X, r.cells, r.region, r.steps; r.deformed(k) = X + displacement of saved step k
"""
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np


class Result:
    def __init__(self, h5):
        self.file = h5py.File(h5, "r")
        self.times = np.array([float(t.get("Value")) for t in ET.parse(h5[:-3] + ".xdmf").iter("Time")])
        self.X = self.file["/mesh/X"][:]  # reference node positions [m]
        self.cells = self.file["/mesh/cells"][:]
        self.region = self.file["/mesh/cell_region"][:]  # volume region id per cell
        # Saved steps in time order; a file still being written may hold one more than the XDMF.
        self.steps = sorted(self.file["/steps"].keys())[: len(self.times)]

    def deformed(self, k):
        """Node positions [m] at saved step k."""
        return self.X + self.file["/steps/" + self.steps[k] + "/displacement"][:]


def open_result(h5, script):
    try:
        return Result(h5)
    except (OSError, KeyError, ET.ParseError) as e:
        sys.exit(f"{script}: {h5}: not a morphfem result ({e})")
