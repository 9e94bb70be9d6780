"""Path planning for a 2-d wire loop game (thesis §2.6.1, Eq. 2.80–2.83, Figures 2.21–2.22).

A robot with two rotary joints (arms of lengths 4 and 2) carries a loop, the segment from the point at
distance 2 to the point at distance 3 along its second arm. The wire is the boundary of a set ``Y``
(here a wavy disc, a polygon with :class:`SepPolygon`). A configuration ``x = (x1, x2)`` is feasible
when the loop crosses the wire, its inner end inside ``Y`` and its outer end outside:

    M = {x | f2(x) ∈ Y and f3(x) ∉ Y} = f2⁻¹(Y) ∩ f3⁻¹(~Y),
    f_ℓ(x) = 4 (cos x1, sin x1) + ℓ (cos(x1 + x2), sin(x1 + x2)),             (Eq. 2.80–2.81)

with the separator ``S_M = f2⁻¹(S_Y) ∩ f3⁻¹(~S_Y)`` (Eq. 2.82). The inner boxes of the paving (proved
feasible) form a graph (boxes sharing a face segment are adjacent); a shortest path in that graph
(Dijkstra between box centres, :mod:`scipy.sparse.csgraph` when available, else a numpy BFS) joins two
configurations, and the polyline centre → shared-face midpoint → next centre stays in proved-feasible
boxes, so every configuration along it is feasible (Figure 2.22 a). Figure 2.22 b shows the motion.

Usage: ``python examples/path_planning.py [--out DIR] [--eps EPS]``; writes ``DIR/path_planning.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, Function, SepInverse, SepPolygon, cos, pave, sin

L1, L_IN, L_OUT = 4.0, 2.0, 3.0  # first arm, inner and outer ends of the loop along the second arm
FRAME = Box([(-np.pi, np.pi), (-np.pi, np.pi)])


def wire_polygon(n: int = 72) -> np.ndarray:
    """The set ``Y``: a wavy disc ``r(φ) = 5 + 0.3 sin 5φ + 0.2 cos 3φ``, as an ``(n, 2)`` polygon."""
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 5.0 + 0.3 * np.sin(5 * phi) + 0.2 * np.cos(3 * phi)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi)])


def f_ell(ell: float) -> Function:
    """``f_ℓ`` of Eq. 2.81 (a map ``R² → R²``)."""
    return Function(
        lambda x: (cos(x[0]) * L1 + cos(x[0] + x[1]) * ell, sin(x[0]) * L1 + sin(x[0] + x[1]) * ell)
    )


def f_ell_points(x: np.ndarray, ell: float) -> np.ndarray:
    """``f_ℓ`` on ``(N, 2)`` configurations (floats)."""
    a, b = x[:, 0], x[:, 0] + x[:, 1]
    return np.column_stack([L1 * np.cos(a) + ell * np.cos(b), L1 * np.sin(a) + ell * np.sin(b)])


def separator(poly: np.ndarray | None = None):
    """``S_M = f2⁻¹(S_Y) ∩ f3⁻¹(~S_Y)`` (Eq. 2.82)."""
    s_y = SepPolygon(wire_polygon() if poly is None else poly)
    return SepInverse(f_ell(L_IN), s_y) & SepInverse(f_ell(L_OUT), ~s_y)


def point_in_polygon(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon test (floats) for ``(N, 2)`` points."""
    a, b = poly, np.roll(poly, -1, axis=0)
    x, y = pts[:, 0, None], pts[:, 1, None]
    crosses = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return (crosses & (x < xi)).sum(axis=1) % 2 == 1


def feasible(x: np.ndarray, poly: np.ndarray | None = None) -> np.ndarray:
    """Point test of Eq. 2.80 for ``(N, 2)`` configurations."""
    poly = wire_polygon() if poly is None else poly
    return point_in_polygon(f_ell_points(x, L_IN), poly) & ~point_in_polygon(f_ell_points(x, L_OUT), poly)


# ---- graph of boxes ---------------------------------------------------------------------------------


def box_adjacency(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(i, j)``, ``i < j``, of 2-d boxes sharing a face segment of positive length.

    Paver boxes tile the plane with exactly shared coordinates (bisection midpoints and contraction
    bounds are cut once), so faces are matched with exact float equality: for each axis ``k``, the boxes
    ``j`` with ``lo_j[k] == hi_i[k]`` are found by binary search, then kept if they overlap ``i`` with
    positive length on the other axis. The cost is the number of such candidate pairs, not ``N²``.
    """
    n = len(lo)
    ii, jj = [], []
    for k in range(2):
        other = 1 - k
        order = np.argsort(lo[:, k], kind="stable")
        keys = lo[order, k]
        left = np.searchsorted(keys, hi[:, k], side="left")
        count = np.searchsorted(keys, hi[:, k], side="right") - left
        i = np.repeat(np.arange(n), count)
        offset = np.arange(i.size) - np.repeat(np.cumsum(count) - count, count)
        j = order[left[i] + offset]
        overlap = np.minimum(hi[i, other], hi[j, other]) - np.maximum(lo[i, other], lo[j, other])
        keep = overlap > 0
        ii.append(np.minimum(i[keep], j[keep]))
        jj.append(np.maximum(i[keep], j[keep]))
    i, j = np.concatenate(ii), np.concatenate(jj)
    return i[i != j], j[i != j]


def shared_face_midpoint(lo: np.ndarray, hi: np.ndarray, i: int, j: int) -> np.ndarray:
    """Midpoint of the segment shared by two touching boxes."""
    a, b = np.maximum(lo[i], lo[j]), np.minimum(hi[i], hi[j])
    return (a + b) / 2


def _components(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    try:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        g = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
        return connected_components(g, directed=False)[1]
    except ImportError:  # label propagation with numpy
        lab = np.arange(n)
        while True:
            new = lab.copy()
            np.minimum.at(new, i, lab[j])
            np.minimum.at(new, j, lab[i])
            if np.array_equal(new, lab):
                return lab
            lab = new


def shortest_box_path(
    lo: np.ndarray, hi: np.ndarray, i: np.ndarray, j: np.ndarray, start: int, goal: int
) -> list[int]:
    """Box indices of a shortest path (Dijkstra on centre distances; BFS without scipy). ``[]`` if none."""
    n = len(lo)
    c = (lo + hi) / 2
    try:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        w = np.linalg.norm(c[i] - c[j], axis=1) + 1e-12
        g = coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
        dist, pred = dijkstra(g, directed=False, indices=start, return_predecessors=True)
        if not np.isfinite(dist[goal]):
            return []
        pred = np.where(pred < 0, -1, pred)
    except ImportError:  # frontier BFS with numpy
        pred = np.full(n, -1)
        seen = np.zeros(n, dtype=bool)
        seen[start] = True
        frontier = np.array([start])
        src, dst = np.concatenate([i, j]), np.concatenate([j, i])
        order = np.argsort(src, kind="stable")
        src, dst = src[order], dst[order]
        while frontier.size and not seen[goal]:
            m = np.isin(src, frontier)
            s, d = src[m], dst[m]
            new = ~seen[d]
            s, d = s[new], d[new]
            d, first = np.unique(d, return_index=True)
            pred[d], seen[d] = s[first], True
            frontier = d
        if not seen[goal]:
            return []
    path = [goal]
    while path[-1] != start:
        path.append(int(pred[path[-1]]))
    return path[::-1]


def path_polyline(lo: np.ndarray, hi: np.ndarray, boxes: list[int]) -> np.ndarray:
    """Centre → shared-face midpoint → centre …: each segment lies inside one (convex) box."""
    pts = [(lo[boxes[0]] + hi[boxes[0]]) / 2]
    for a, b in zip(boxes[:-1], boxes[1:], strict=True):
        pts.append(shared_face_midpoint(lo, hi, a, b))
        pts.append((lo[b] + hi[b]) / 2)
    return np.array(pts)


def run(eps: float = 0.02, out: str | Path | None = None) -> dict:
    """Pave M, find a path across the largest connected inner region; draw Figure 2.22 into ``out``."""
    t0 = time.perf_counter()
    p = pave(FRAME, separator(), eps)
    t1 = time.perf_counter()
    lo, hi = p.inner
    i, j = box_adjacency(lo, hi)
    comp = _components(len(lo), i, j)
    # the component with the largest area; start and goal are its extreme boxes in x1
    area = np.bincount(comp, weights=np.prod(hi - lo, axis=1))
    members = np.flatnonzero(comp == np.argmax(area))
    cx = (lo[members, 0] + hi[members, 0]) / 2
    start, goal = int(members[np.argmin(cx)]), int(members[np.argmax(cx)])
    boxes = shortest_box_path(lo, hi, i, j, start, goal)
    poly = path_polyline(lo, hi, boxes) if boxes else np.zeros((0, 2))
    t2 = time.perf_counter()
    res = {
        "eps": eps, "inner_area": p.inner_area, "boundary_area": p.boundary_area, "n_inner": len(lo),
        "n_boundary": len(p.boundary[0]), "bisections": p.bisections, "n_edges": len(i),
        "n_components": int(comp.max() + 1) if len(comp) else 0, "start": poly[0] if len(poly) else None,
        "goal": poly[-1] if len(poly) else None, "path_boxes": boxes, "path": poly,
        "path_length": float(np.linalg.norm(np.diff(poly, axis=0), axis=1).sum()) if len(poly) else 0.0,
        "pave_seconds": t1 - t0, "graph_seconds": t2 - t1, "paving": p,
    }  # fmt: skip
    if out is not None:
        res["png"] = draw(p, poly, out)
    return res


def draw(p, poly: np.ndarray, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, draw_polygon, new_figure

    fig, (a, b) = new_figure(ncols=2, size=6)
    draw_paving(p, a, frame=FRAME, linewidth=0.05, title="(a) configuration space M and a feasible path")
    if len(poly):
        a.plot(poly[:, 0], poly[:, 1], "k-", linewidth=1.5, zorder=5)
        a.plot(*poly[0], "go", *poly[-1], "ms", zorder=6)
    a.set_xlabel("x1")
    a.set_ylabel("x2")
    y = wire_polygon()
    draw_polygon(y, b, edgecolor="k", facecolor="0.85", linewidth=1.5, zorder=1)
    if len(poly):
        k = np.linspace(0, len(poly) - 1, 14).round().astype(int)
        q = poly[k]
        elbow = L1 * np.column_stack([np.cos(q[:, 0]), np.sin(q[:, 0])])
        f2, f3 = f_ell_points(q, L_IN), f_ell_points(q, L_OUT)
        shade = np.linspace(0.15, 0.85, len(q))
        for e, g2, g3, s in zip(elbow, f2, f3, shade, strict=True):
            col = (s, 0.2, 1 - s)
            b.plot([0, e[0], g2[0]], [0, e[1], g2[1]], "-", color=col, linewidth=1.0, alpha=0.7)
            b.plot([g2[0], g3[0]], [g2[1], g3[1]], "-", color=col, linewidth=3.0)
        b.plot(*f_ell_points(poly, L_IN).T, "r-", linewidth=0.8)
        b.plot(*f_ell_points(poly, L_OUT).T, "b-", linewidth=0.8)
    b.plot(0, 0, "ko")
    b.set_aspect("equal")
    b.set_xlim(-7.5, 7.5)
    b.set_ylim(-7.5, 7.5)
    b.set_title("(b) the motion in the world (loop in thick lines)")
    fig.suptitle(f"§2.6.1 wire loop game, ε = {p.eps:g}")
    return save_figure(fig, out, "path_planning.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.02)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(
        f"Wire loop game at eps={r['eps']:g}: paving {r['pave_seconds']:.2f} s, "
        f"graph {r['graph_seconds']:.2f} s"
    )
    print(
        f"  inner area {r['inner_area']:.4f}, undetermined {r['boundary_area']:.4f}, "
        f"{r['n_inner']} inner boxes, "
        f"{r['n_edges']} adjacencies, {r['n_components']} connected components"
    )
    if r["path_boxes"]:
        print(
            f"  path of {len(r['path_boxes'])} boxes from x = {np.round(r['start'], 3).tolist()} to "
            f"{np.round(r['goal'], 3).tolist()}, length {r['path_length']:.3f} rad"
        )
    else:
        print("  no path found")
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
