#!/usr/bin/env python3
"""Whether the walls of a run's chambers pass through each other, per saved step.

For each chamber (the volume region named bladder_K, from the result's region names, or
--bladder-regions for results written before the names were stored) it takes the
cavity's inner surface: the mesh boundary faces of the chamber's cells, less those on
the end planes y = min / max of the mesh (a plane-strain slice is open there), split into
edge-connected pieces; the cavity's is the piece that is closed (but on the end planes)
and encloses a positive volume with its normals out of the wall (the outer wall surface
ends at the bond strip), the smallest by area if several or none do. A P2 face is cut
into 4 flat triangles at its mid-edge nodes. At the first step the volume the surface
encloses is checked against the run's tables/cavities (column bK_volume_m3, first row):
a warning if they differ by more than 3 %.

Prints, per shown step, for each chamber: the number of pairs of surface triangles that
share no node and cross each other (an edge of one passes through the other; coplanar
touching is not counted) and the gap [mm]: the smallest distance from a surface vertex to
a triangle of the facing wall (whose reference normal is opposed to the vertex's by more
than 120 deg; at rest the cavity's height), negative when the vertex is behind the plane
of its nearest facing triangle, i.e. has gone through the wall; '-' where no facing
triangle is within 1 mm (or the largest triangle's size, if larger). Ends with a line per
chamber: the steps with crossings (first, last, most pairs) and the smallest gap.

Without self-contact nothing keeps a collapsing chamber's walls apart and they may pass
through each other: this tells whether a run needed the chambers' self-contact, and from
when. The cavity volume alone does not: walls that cross in a figure eight leave two
lobes of opposite sign, and the net volume can stay well positive.

    /usr/bin/python3 scripts/chamber_walls.py RESULTS/CASE.h5 [T_FROM T_TO] [--every N]
                     [--bladder-regions 1,2,...]

The times come from the XDMF beside the .h5 (or, without one, from the steps' time
attribute). --every N shows every N-th step (of those in the window if one is given).
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from result_regions import bladder_regions

PROG = "chamber_walls.py"

# Faces of a tetrahedron by its corners (each opposite one corner); orientation is fixed
# from the geometry below.
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
# Mid-edge node orders of the 10-node tetrahedron: VTK (fem/element.h, what the project
# writes) and gmsh; the one the reference coordinates agree with is used.
P2_ORDERS = {
    "VTK": [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
    "gmsh": [(0, 1), (1, 2), (2, 0), (0, 3), (2, 3), (1, 3)],
}
VOLUME_TOLERANCE = 0.03
GAP_REACH = 1e-3  # [m] the gap is searched up to this far (or a triangle's size, if larger)


def fail(path, what):
    sys.exit(f"{PROG}: {path}: {what}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("h5", help="the run's HDF5 file (its XDMF beside it gives the times)")
    parser.add_argument("window", nargs="*", type=float, help="optional time window [s]: from to")
    parser.add_argument("--every", type=int, default=1, help="show every N-th step (default 1)")
    parser.add_argument("--bladder-regions", help="region ids of bladders 1..K, comma-separated, for results "
                        "written before region names were stored (e.g. 1,2,3,4,5,6,7,8 for the 3D physical preset)")
    args = parser.parse_intermixed_args()
    if len(args.window) not in (0, 2):
        sys.exit(f"{PROG}: the time window needs two numbers (from to)")
    if args.every < 1:
        sys.exit(f"{PROG}: --every needs a positive integer")
    if not os.path.isfile(args.h5):
        fail(args.h5, "no such file")
    try:
        f = h5py.File(args.h5, "r")
        X = f["/mesh/X"][:]
        cells = f["/mesh/cells"][:]
        region = f["/mesh/cell_region"]
        cell_region = region[:]
        steps = sorted(f["/steps"].keys())
    except (OSError, KeyError) as e:
        fail(args.h5, f"not a morphfem result ({e})")
    times = read_times(args.h5, f, steps)
    ids = bladder_regions(PROG, args.h5, region, args.bladder_regions)
    shown = [i for i, t in enumerate(times) if not args.window or args.window[0] <= t <= args.window[1]]
    shown = shown[:: args.every]
    if not shown:
        fail(args.h5, "no saved step in the time window")
    if cells.ndim != 2 or cells.shape[1] not in (4, 10) or X.ndim != 2 or X.shape[1] != 3:
        fail(args.h5, f"mesh/cells {cells.shape} is not 4- or 10-node tetrahedra on 3D nodes")

    surfaces = {}
    for k, rid in ids:
        if not np.any(cell_region == rid):
            fail(args.h5, f"no cells in region {rid} (bladder_{k})")
        surfaces[k] = cavity_surface(args.h5, X, cells, cell_region, rid)
    if cells.shape[1] == 10:
        print(f"P2 mesh: mid-edge nodes in {p2_order(args.h5, X, cells)[0]} order; each 6-node face cut into 4 triangles")
    check_volumes(f, X, steps, surfaces)

    header = " ".join(f"{'chamber ' + str(k):>12}" for k, _ in ids)
    print(f"    t [s]  {header}   (chamber: crossing triangle pairs / gap to the facing wall [mm])")
    history = {k: [] for k, _ in ids}
    for i in shown:
        x = X + f["/steps/" + steps[i] + "/displacement"][:]
        cols = []
        for k, _ in ids:
            s = surfaces[k]
            tri = x[s["tris"]]
            n = crossing_pairs(tri, s["tris"])
            gap = facing_gap(x, s)
            history[k].append((times[i], n, gap))
            gap_text = "     -" if np.isnan(gap) else f"{1000 * gap:6.2f}"
            cols.append(f"{n:5d}/{gap_text}")
        print(f"{times[i]:9.3f}  " + " ".join(f"{c:>12}" for c in cols), flush=True)

    print(f"summary over {len(shown)} shown steps, t = {times[shown[0]]:.3f} .. {times[shown[-1]]:.3f} s:")
    for k, _ in ids:
        h = history[k]
        crossed = [(t, n) for t, n, _ in h if n > 0]
        gaps = [(g, t) for t, _, g in h if not np.isnan(g)]
        gap_text = f"smallest gap {1000 * min(gaps)[0]:.3f} mm at t = {min(gaps)[1]:.3f} s" if gaps else "no gap found"
        if crossed:
            t_max, n_max = max(crossed, key=lambda c: c[1])
            print(f"  chamber {k}: walls cross at {len(crossed)} steps, first t = {crossed[0][0]:.3f} s, "
                  f"last t = {crossed[-1][0]:.3f} s, most pairs {n_max} at t = {t_max:.3f} s; {gap_text}")
        else:
            print(f"  chamber {k}: no crossing; {gap_text}")


def read_times(path, f, steps):
    """Times of the steps: from the XDMF beside the file, else (none, or not one time a step)
    from the steps' time attribute."""
    xdmf = path[:-3] + ".xdmf" if path.endswith(".h5") else None
    if xdmf and os.path.exists(xdmf):
        try:
            times = [float(t.get("Value")) for t in ET.parse(xdmf).iter("Time")]
        except (ET.ParseError, TypeError, ValueError) as e:
            fail(path, f"cannot read the times from {xdmf} ({e})")
        if len(times) == len(steps):
            return times
    try:
        return [float(f["/steps/" + s].attrs["time"]) for s in steps]
    except KeyError:
        if xdmf and os.path.exists(xdmf):
            fail(path, f"{xdmf} has {len(times)} times for {len(steps)} saved steps, and the steps no time attribute")
        fail(path, "no times (no XDMF beside it and the steps have no time attribute)")


def p2_order(path, X, cells):
    """(name, local mid-edge node of each corner pair) for 10-node cells, from the geometry:
    a mid-edge node sits at its edge's middle in the reference (straight-sided mesh)."""
    sample = cells[:: max(1, len(cells) // 2000)]
    size = np.linalg.norm(X[sample[:, 1]] - X[sample[:, 0]], axis=1).mean()
    best = None
    for name, edges in P2_ORDERS.items():
        err = max(np.abs(X[sample[:, 4 + e]] - 0.5 * (X[sample[:, i]] + X[sample[:, j]])).max()
                  for e, (i, j) in enumerate(edges))
        if best is None or err < best[1]:
            best = (name, err, edges)
    if best[1] > 0.1 * size:
        fail(path, f"10-node cells: no known mid-edge node order fits the mesh (best {best[0]}, "
             f"off by {best[1]:.3g} m)")
    mid = {}
    for e, (i, j) in enumerate(best[2]):
        mid[(i, j)] = mid[(j, i)] = 4 + e
    return best[0], mid


def cavity_surface(path, X, cells, cell_region, rid):
    """The inner surface of region rid's cavity as flat triangles (node ids, each oriented
    with its normal out of the wall, i.e. into the cavity) and what the gap needs."""
    own = np.where(cell_region == rid)[0]
    # Boundary faces of the whole mesh: corner triples that belong to exactly one cell.
    all_faces = np.sort(cells[:, TET_FACES].reshape(-1, 3), axis=1)
    _, inverse, counts = np.unique(all_faces, axis=0, return_inverse=True, return_counts=True)
    boundary = (counts[inverse.ravel()] == 1).reshape(-1, 4)[own]
    cell_of, local = np.nonzero(boundary)
    cell_of = own[cell_of]
    corners = TET_FACES[local]  # local corner numbers (n, 3)
    faces = np.take_along_axis(cells[cell_of][:, :4], corners, axis=1)
    # Leave out the faces on the end planes of the mesh.
    y = X[:, 1]
    tol = 1e-9 * np.ptp(X, axis=0).max()
    on_end = (np.abs(y[faces] - y.min()) < tol).all(1) | (np.abs(y[faces] - y.max()) < tol).all(1)
    faces, cell_of, corners = faces[~on_end], cell_of[~on_end], corners[~on_end]
    if len(faces) == 0:
        fail(path, f"region {rid} has no boundary faces (no cavity)")
    # Orient each face out of its cell: the opposite corner behind it.
    opposite = cells[cell_of, 6 - corners.sum(1)]
    a, b, c = X[faces[:, 0]], X[faces[:, 1]], X[faces[:, 2]]
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), X[opposite] - a) > 0
    faces[flip] = faces[flip][:, [0, 2, 1]]
    corners[flip] = corners[flip][:, [0, 2, 1]]
    # Edge-connected pieces. The cavity's inner surface is closed (every edge in two of its
    # faces, but for the edges on the end planes) and encloses a positive volume with its
    # normals out of the wall; the outer wall surface ends at the bond strip or the skin
    # (or, closed around a free tube, encloses a negative one). If several pieces qualify,
    # or none, the smallest by area is taken.
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique_edges, edge_id = np.unique(edges, axis=0, return_inverse=True)
    edge_id = edge_id.ravel()
    face_id = np.tile(np.arange(len(faces)), 3)
    incidence = coo_matrix((np.ones(len(face_id)), (face_id, edge_id))).tocsr()
    n_pieces, piece = connected_components(incidence @ incidence.T, directed=False)
    a, b, c = X[faces[:, 0]], X[faces[:, 1]], X[faces[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    piece_area = np.bincount(piece, weights=area, minlength=n_pieces)
    ey = y[unique_edges]
    edge_on_end = (np.abs(ey - y.min()) < tol).all(1) | (np.abs(ey - y.max()) < tol).all(1)
    open_edge = (np.bincount(edge_id) == 1) & ~edge_on_end
    closed = np.bincount(piece[face_id[open_edge[edge_id]]], minlength=n_pieces) == 0
    volume = np.array([enclosed_volume(X, faces[piece == q]) for q in range(n_pieces)])
    cavity = closed & (volume > 0)
    choice = "closed, encloses a positive volume" if cavity.any() else "none closed around a volume: smallest"
    if cavity.sum() > 1:
        choice = f"{cavity.sum()} closed around a volume, the smallest"
    candidates = np.where(cavity)[0] if cavity.any() else np.arange(n_pieces)
    chosen = candidates[np.argmin(piece_area[candidates])]
    inner = piece == chosen
    faces, cell_of, corners = faces[inner], cell_of[inner], corners[inner]
    if cells.shape[1] == 10:
        _, mid = p2_order(path, X, cells)
        local_mid = np.array([[mid[(int(p), int(q))] for p, q in zip(row, np.roll(row, -1))] for row in corners])
        m = np.take_along_axis(cells[cell_of], local_mid, axis=1)  # mid-nodes of edges 01, 12, 20
        tris = np.concatenate([
            np.stack([faces[:, 0], m[:, 0], m[:, 2]], 1),
            np.stack([m[:, 0], faces[:, 1], m[:, 1]], 1),
            np.stack([m[:, 2], m[:, 1], faces[:, 2]], 1),
            np.stack([m[:, 0], m[:, 1], m[:, 2]], 1),
        ])
    else:
        tris = faces
    # Reference unit normals of the triangles and (area-weighted) of the vertices, for the gap.
    verts, tri_local = np.unique(tris, return_inverse=True)
    tri_local = tri_local.reshape(-1, 3)
    p = X[tris]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    vert_normal = np.zeros((len(verts), 3))
    for j in range(3):
        np.add.at(vert_normal, tri_local[:, j], normal)
    unit = lambda v: v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-300)
    return {"tris": tris, "verts": verts, "tri_local": tri_local, "pieces": n_pieces, "choice": choice,
            "area": piece_area[chosen], "tri_normal": unit(normal), "vert_normal": unit(vert_normal)}


def enclosed_volume(x, tris):
    """Volume of the cavity bounded by the triangles (normals into the cavity), by the
    divergence theorem with the field (x, 0, z) / 2: exact for a closed surface and for
    one open only on planes y = const (a plane-strain slice)."""
    p = x[tris]
    area_vector = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    centroid = p.mean(1)
    return -0.5 * np.sum(centroid[:, 0] * area_vector[:, 0] + centroid[:, 2] * area_vector[:, 2])


def check_volumes(f, X, steps, surfaces):
    """Compare each surface's enclosed volume at the first step with the cavity table's first row."""
    x = X + f["/steps/" + steps[0] + "/displacement"][:]
    columns = []
    if "tables/cavities" in f:
        table = f["tables/cavities"]
        columns = [c.decode() if isinstance(c, bytes) else str(c) for c in table.attrs.get("columns", [])]
        first = table[0] if len(table) else None
    parts = []
    for k, s in surfaces.items():
        v = enclosed_volume(x, s["tris"])
        text = f"chamber {k}: {len(s['tris'])} triangles, {1e6 * s['area']:.0f} mm^2 (of {s['pieces']} pieces: {s['choice']}), " \
               f"encloses {v:.4g} m^3"
        column = f"b{k}_volume_m3"
        if column in columns and first is not None:
            ref = float(first[columns.index(column)])
            text += f", table {ref:.4g} m^3"
            if not abs(v - ref) <= VOLUME_TOLERANCE * abs(ref):
                text += f"  WARNING: differs by {100 * (v - ref) / ref:+.1f} %, the surface may not be the cavity's"
        else:
            text += f" (no {column} in tables/cavities to check against)"
        parts.append(text)
    print("cavity surfaces at the first step:\n  " + "\n  ".join(parts))


def orient(a, b, c, d):
    """Six times the signed volume of the tetrahedron abcd, row-wise."""
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))


def segments_cross(p, q, a, b, c):
    """Row-wise: does the open segment pq pass through the triangle abc (not just touch it)?"""
    s1, s2 = orient(a, b, c, p), orient(a, b, c, q)
    t1, t2, t3 = orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)
    return (s1 * s2 < 0) & (((t1 > 0) & (t2 > 0) & (t3 > 0)) | ((t1 < 0) & (t2 < 0) & (t3 < 0)))


def crossing_pairs(tri, nodes):
    """Number of pairs of triangles (coordinates tri (m, 3, 3), node ids nodes (m, 3)) that
    share no node and cross: an edge of either passes through the other."""
    centroid = tri.mean(1)
    radius = np.linalg.norm(tri - centroid[:, None], axis=2).max(1)
    pairs = cKDTree(centroid).query_pairs(2 * radius.max() * (1 + 1e-9), output_type="ndarray")
    if len(pairs) == 0:
        return 0
    i, j = pairs[:, 0], pairs[:, 1]
    near = np.linalg.norm(centroid[i] - centroid[j], axis=1) <= (radius[i] + radius[j]) * (1 + 1e-9)
    i, j = i[near], j[near]
    apart = ~(nodes[i][:, :, None] == nodes[j][:, None, :]).any(axis=(1, 2))
    i, j = i[apart], j[apart]
    if len(i) == 0:
        return 0
    origin = centroid[i]
    A, B = tri[i] - origin[:, None], tri[j] - origin[:, None]
    hit = np.zeros(len(i), dtype=bool)
    for one, other in ((A, B), (B, A)):
        for e in range(3):
            hit |= segments_cross(one[:, e], one[:, (e + 1) % 3], other[:, 0], other[:, 1], other[:, 2])
    return int(hit.sum())


def point_segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - a - t[:, None] * ab, axis=1)


def point_triangle_distance(p, a, b, c):
    """Row-wise distance from the point p to the triangle abc."""
    n = np.cross(b - a, c - a)
    nn = np.maximum(np.einsum("ij,ij->i", n, n), 1e-300)
    inside = ((np.einsum("ij,ij->i", np.cross(b - a, p - a), n) >= 0)
              & (np.einsum("ij,ij->i", np.cross(c - b, p - b), n) >= 0)
              & (np.einsum("ij,ij->i", np.cross(a - c, p - c), n) >= 0))
    plane = np.abs(np.einsum("ij,ij->i", p - a, n)) / np.sqrt(nn)
    edge = np.minimum(np.minimum(point_segment_distance(p, a, b), point_segment_distance(p, b, c)),
                      point_segment_distance(p, c, a))
    return np.where(inside, plane, edge)


def facing_gap(x, s):
    """Smallest signed distance from a vertex of the surface to the nearest triangle of the
    facing wall (not one of its own, reference normals opposed by more than 120 deg),
    negative when the vertex lies behind that triangle's plane (through the wall), searched
    within the largest triangle's size; nan if no vertex has a facing triangle so near."""
    tri = x[s["tris"]]
    centroid = tri.mean(1)
    radius = np.linalg.norm(tri - centroid[:, None], axis=2).max(1)
    points = x[s["verts"]]
    reach = max(GAP_REACH, radius.max())
    # A triangle within reach of a point has its centroid within reach + its radius.
    near = cKDTree(points).sparse_distance_matrix(cKDTree(centroid), reach + radius.max(), output_type="ndarray")
    v, t = near["i"], near["j"]
    keep = (~(s["tri_local"][t] == v[:, None]).any(1)) & \
           (np.einsum("ij,ij->i", s["vert_normal"][v], s["tri_normal"][t]) < -0.5)
    v, t = v[keep], t[keep]
    if len(v) == 0:
        return float("nan")
    d = point_triangle_distance(points[v], tri[t, 0], tri[t, 1], tri[t, 2])
    order = np.lexsort((d, v))  # each vertex's nearest facing triangle first
    first = order[np.r_[True, v[order][1:] != v[order][:-1]]]
    first = first[d[first] <= reach]
    if len(first) == 0:
        return float("nan")
    v, t, d = v[first], t[first], d[first]
    normal = np.cross(tri[t, 1] - tri[t, 0], tri[t, 2] - tri[t, 0])  # into the cavity
    behind = np.einsum("ij,ij->i", points[v] - tri[t, 0], normal) < 0
    return float(np.where(behind, -d, d).min())


if __name__ == "__main__":
    main()
