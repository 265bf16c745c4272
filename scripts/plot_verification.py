#!/usr/bin/python3
"""Plots verification records (JSON lines from `morphfem verify`): for each case,
relative error against wall time (log-log), one line per quantity and element
order, so speed is always shown against error.

usage: plot_verification.py RECORDS.jsonl OUT_DIR
"""
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    records = []
    with open(sys.argv[1]) as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                records.append(json.loads(line))
            except json.JSONDecodeError as e:
                sys.exit(f"{sys.argv[1]}:{number}: not a JSON object ({e})")
    by_case = defaultdict(list)
    for r in records:
        by_case[r["case"]].append(r)
    os.makedirs(sys.argv[2], exist_ok=True)
    for case, rows in by_case.items():
        series = defaultdict(list)
        for r in rows:
            if r["rel_error"] is None or r["rel_error"] <= 0:
                continue
            series[(r["quantity"], r["order"])].append((r["wall_s"], r["rel_error"], r["dofs"]))
        if not series:
            continue
        fig, ax = plt.subplots(figsize=(7, 5))
        for (quantity, order), points in sorted(series.items()):
            points.sort()
            ax.loglog([p[0] for p in points], [p[1] for p in points], "o-" if order == 2 else "s--",
                      label=f"P{order} {quantity}")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error")
        ax.set_title(f"{case}: error against wall time (mesh ladder)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        path = os.path.join(sys.argv[2], f"{case}.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
