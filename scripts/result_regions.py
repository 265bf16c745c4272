"""Region lookup shared by the scripts that read a morphfem result (.h5)."""
import sys


def bladder_regions(prog, h5, region, override=None):
    """[(K, region id)] of the volume regions named bladder_K, sorted by K.

    region is the result's /mesh/cell_region dataset (its "names" attribute holds
    "ID NAME" entries); override, a comma-separated list of the region ids of
    bladders 1..K, serves results written before the names were stored. Exits with
    "PROG: ..." on bad input.
    """
    names = {}
    if override:
        try:
            names = {f"bladder_{k + 1}": int(r) for k, r in enumerate(override.split(","))}
        except ValueError:
            sys.exit(f"{prog}: --bladder-regions {override}: not comma-separated integers")
    elif "names" in region.attrs:
        for entry in region.attrs["names"]:
            rid, name = (entry.decode() if isinstance(entry, bytes) else str(entry)).split(" ", 1)
            names[name] = int(rid)
    else:
        sys.exit(f"{prog}: {h5}: no region names (written before they were stored); give --bladder-regions")
    ids = sorted((int(n.split("_")[1]), i) for n, i in names.items() if n.startswith("bladder_") and n[8:].isdigit())
    if not ids:
        sys.exit(f"{prog}: {h5}: no bladder_K regions")
    return ids
