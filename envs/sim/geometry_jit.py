"""Compiled kernels of the simulator's exact geometry: sector distances and point-edge distances.

Each kernel loops over the world's edges in machine code (:func:`digslam.observer.core.scalar_jit.njit`),
with the
bounding-box pre-filter fused in (an edge whose box lies farther than
``reach`` from the point is skipped; ``reach = inf`` keeps every edge). :func:`sector_kernel` and
:func:`points_edges_kernel` compute float64 values, with the same formulas as the numpy versions that are
their test oracles in ``tests/envs/sim/test_kernels.py``:

* :func:`sector_kernel` -- the sonar distance of thesis Eq. (4.22), ``d = inf {d | f(S_1, d) ∩ not M ≠ ∅}``:
  the nearest edge point inside each circular sector (exact, no ray fan): per edge,
  the minimum of the convex distance over the edge's part inside the sector is reached at the foot of the
  perpendicular, at an endpoint inside the sector, or where the edge crosses a boundary ray. A sector of
  half-aperture ``pi`` is the whole plane: its distance is the plain point-edge distance. An edge whose
  nearest point is no nearer than a sector's best so far is skipped for that sector (none of its points
  can improve it).
* :func:`points_edges_kernel` -- distance from points to the nearest edge.
* :func:`sector_bounds_kernel` -- rigorous bounds of the TRUE sector distance (from the true pose, within
  the simulator's proved pose error, floating point included): the record's range intervals are built on
  them, while :func:`sector_kernel` gives the float value the rewards and the rendering use.
* :func:`sense_kernel` -- both of the above in one pass over the edges, bit for bit (the env's step).

The robot's swept-disc checks (:mod:`.robot_jit`) reuse the scalar helpers :func:`edge_near` and
:func:`segment_distance`.

Example (a cone facing a wall 2 m away, and one facing away from it):
    >>> import numpy as np
    >>> edges = np.array([[2.0, -1.0, 2.0, 1.0]])
    >>> d = np.empty(2); w = np.empty((2, 2))
    >>> sector_kernel(0.0, 0.0, 0.0, np.array([0.0, np.pi]), np.array([0.3, 0.3]), np.full(2, np.inf),
    ...               edges, edge_boxes(edges), np.inf, d, w)
    >>> d.tolist(), w[0].tolist()
    ([2.0, inf], [2.0, 0.0])
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.observer.core.rounding import LIBM_ULPS
from digslam.observer.core.scalar_jit import add_up, njit, sub_dn

_INF = math.inf


def edge_boxes(edges: np.ndarray) -> np.ndarray:
    """Bounding boxes ``(E, 4)`` (xmin, ymin, xmax, ymax), C-contiguous float64, of an edge array."""
    e = np.asarray(edges, dtype=np.float64).reshape(-1, 4)
    return np.ascontiguousarray(
        np.stack(
            [
                np.minimum(e[:, 0], e[:, 2]),
                np.minimum(e[:, 1], e[:, 3]),
                np.maximum(e[:, 0], e[:, 2]),
                np.maximum(e[:, 1], e[:, 3]),
            ],
            axis=1,
        )  # fmt: skip
    )


@njit(forceinline=True)
def edge_near(bbox: np.ndarray, k: int, x: float, y: float, reach2: float) -> bool:
    """Whether the bounding box ``bbox[k]`` (:func:`edge_boxes`) of edge ``k`` comes within ``sqrt(reach2)``
    of ``(x, y)`` (the pre-filter of the edge loops; ``reach2 = inf`` keeps every edge)."""
    dx = max(max(bbox[k, 0] - x, x - bbox[k, 2]), 0.0)
    dy = max(max(bbox[k, 1] - y, y - bbox[k, 3]), 0.0)
    return dx * dx + dy * dy <= reach2


@njit(forceinline=True)
def segment_distance(ax: float, ay: float, dx: float, dy: float) -> float:
    """Distance (float64, not rounded outward) from the origin to the segment ``a + t d``, ``t in [0, 1]``:
    the distance to the foot of the perpendicular, clamped to the segment."""
    dd = dx * dx + dy * dy
    t = 0.0
    if dd > 0.0:
        t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
    px, py = ax + t * dx, ay + t * dy
    return math.sqrt(px * px + py * py)


@njit
def sector_kernel(x: float, y: float, th: float, alpha: np.ndarray, gamma: np.ndarray, cut: np.ndarray,
                  edges: np.ndarray, bbox: np.ndarray, reach: float, dist: np.ndarray,
                  wit: np.ndarray) -> None:  # fmt: skip
    """Nearest edge point from ``(x, y)`` inside each sector ``(th + alpha[s], gamma[s])``, written in place.

    ``dist[s]`` is the distance, ``inf`` if no kept edge meets the unbounded sector or if it exceeds
    ``cut[s]``, and ``wit[s]`` the nearest point (NaN where the distance is ``inf``). Half-apertures must
    lie in ``(0, pi]``.
    """
    S, E = alpha.shape[0], edges.shape[0]
    ux, uy, cg = np.empty(S), np.empty(S), np.empty(S)
    wx, wy = np.empty((S, 2)), np.empty((S, 2))
    for s in range(S):
        a = th + alpha[s]
        ux[s], uy[s], cg[s] = math.cos(a), math.sin(a), math.cos(gamma[s])
        wx[s, 0], wy[s, 0] = math.cos(a - gamma[s]), math.sin(a - gamma[s])
        wx[s, 1], wy[s, 1] = math.cos(a + gamma[s]), math.sin(a + gamma[s])
        dist[s] = _INF
        wit[s, 0], wit[s, 1] = np.nan, np.nan
    reach2 = reach * reach
    px, py, nrm = np.empty(3), np.empty(3), np.empty(3)
    for k in range(E):
        if not edge_near(bbox, k, x, y, reach2):
            continue
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        dx, dy = edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]
        dd = dx * dx + dy * dy
        px[0], py[0], px[1], py[1] = ax, ay, ax + dx, ay + dy
        npts = 2
        if dd > 0.0:  # zero-length edges have no foot: their endpoints suffice
            t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
            px[2], py[2] = ax + t * dx, ay + t * dy
            npts = 3
        for j in range(npts):
            nrm[j] = math.hypot(px[j], py[j])
        near = npts - 1  # the nearest point of the edge: its foot, or its nearer endpoint
        if npts == 2 and nrm[1] < nrm[0]:
            near = 1
        cross = ax * dy - ay * dx
        for s in range(S):
            if nrm[near] >= dist[s]:  # no point of this edge is nearer than what sector s already has
                continue
            if gamma[s] >= math.pi:  # the whole plane
                dist[s], wit[s, 0], wit[s, 1] = nrm[near], px[near] + x, py[near] + y
                continue
            for j in range(npts):
                n = nrm[j]
                # angle(u, v) <= gamma  <=>  u.v >= |v| cos(gamma) for gamma in (0, pi]: no angle wrapping
                if n < dist[s] and ux[s] * px[j] + uy[s] * py[j] >= n * cg[s]:
                    dist[s], wit[s, 0], wit[s, 1] = n, px[j] + x, py[j] + y
            for b in range(2):  # boundary rays r w (r >= 0) crossing a + s d (s in [0, 1])
                den = wx[s, b] * dy - wy[s, b] * dx
                if den == 0.0:
                    continue
                r = cross / den
                sp = (wy[s, b] * ax - wx[s, b] * ay) / den
                if r >= 0.0 and sp >= 0.0 and sp <= 1.0 and r < dist[s]:
                    dist[s], wit[s, 0], wit[s, 1] = r, r * wx[s, b] + x, r * wy[s, b] + y
    for s in range(S):
        if not dist[s] <= cut[s]:
            dist[s], wit[s, 0], wit[s, 1] = _INF, np.nan, np.nan


@njit(forceinline=True)
def _min_dist(x: float, y: float, edges: np.ndarray, bbox: np.ndarray, reach2: float) -> float:
    best = _INF
    for k in range(edges.shape[0]):
        if edge_near(bbox, k, x, y, reach2):
            ax, ay = edges[k, 0] - x, edges[k, 1] - y
            best = min(best, segment_distance(ax, ay, edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]))
    return best


@njit
def points_edges_kernel(pts: np.ndarray, edges: np.ndarray, bbox: np.ndarray, reach: float,
                        out: np.ndarray) -> None:  # fmt: skip
    """``out[i]``: distance from ``pts[i]`` to the nearest kept edge (``inf`` if none)."""
    reach2 = reach * reach
    for i in range(pts.shape[0]):
        out[i] = _min_dist(pts[i, 0], pts[i, 1], edges, bbox, reach2)


# --- rigorous bounds on the true sector distance (the record's range intervals) -----------------------------
_U = 2.0**-53
_ETA = 5e-324
_LU = LIBM_ULPS * 2.0 * _U  # libm error on a value in [-1, 1]


class _Edge(NamedTuple):
    """One edge relative to the sensor position ``p`` (see :func:`_edge_cone`): ``a = (ax, ay)``,
    ``d = (dx, dy)``, the number ``npts`` of its candidate nearest points (endpoints, foot), ``seg`` a lower
    bound of the whole edge's distance and ``e_pt`` the candidates' position error."""

    ax: float
    ay: float
    dx: float
    dy: float
    npts: int
    seg: float
    e_pt: float


class _ConeBounds(NamedTuple):
    """One cone as :func:`_edge_cone` reads it: the direction ``(ux, uy)`` within ``e_u`` per component,
    ``cos γ = cg`` within ``_LU``, the boundary rays ``w0``, ``w1`` within ``e_w0``, ``e_w1``, the apex
    shift ``sh`` and ``whole`` (the whole plane, ``γ = π``)."""

    ux: float
    uy: float
    cg: float
    w0x: float
    w0y: float
    w1x: float
    w1y: float
    e_u: float
    e_w0: float
    e_w1: float
    sh: float
    whole: bool


@njit(forceinline=True)
def _edge_cone(edge: _Edge, px: np.ndarray, py: np.ndarray, pn: np.ndarray, pe: np.ndarray, cone: _ConeBounds
               ) -> tuple[float, float]:  # fmt: skip
    """Bounds ``(lower, upper)`` on the distance from the apexes ``p ∓ sh u`` to the nearest point of one
    edge inside the exact cone of that apex; see :func:`sector_bounds_kernel`.

    ``edge`` is the edge relative to ``p`` (:class:`_Edge`) and ``(px[j], py[j])`` its candidates
    (``j < edge.npts``), whose computed norms ``pn`` are within ``pe`` of the exact distances of exact edge
    points; ``cone`` the cone with the error bounds of its direction and boundary rays
    (:class:`_ConeBounds`). The lower bound is for the backward apex ``p − sh u`` and keeps every candidate
    that may lie in its cone (``inf`` when none can); the upper bound is for the forward apex ``p + sh u``
    and keeps only candidates proved inside its cone (``inf`` if none is). Moving the apex by ``sh`` moves
    each distance by at most ``sh`` and ``u·q − |q| cos γ`` by at most ``sh (1 + |cos γ|) ≤ 2 sh``, and the
    foot of the shifted apex lies within ``sh`` of ``p``'s (projection onto a segment is 1-Lipschitz;
    ``u·q − |q| cos γ`` is 2-Lipschitz in ``q``), hence the ``4 sh`` in the membership margin; the
    crossings are recomputed for each apex (they are linear in it).
    """
    ax, ay, dx, dy, e_pt = edge.ax, edge.ay, edge.dx, edge.dy, edge.e_pt
    ux, uy, cg, e_u, sh = cone.ux, cone.uy, cone.cg, cone.e_u, cone.sh
    lo, hi = math.inf, math.inf
    for j in range(edge.npts):
        n, e_n = pn[j], pe[j]
        if cone.whole:
            lo, hi = min(lo, n - e_n), min(hi, n + e_n)
            continue
        g = ux * px[j] + uy * py[j] - n * cg
        e_g = (n + e_n) * (2.0 * e_u + _LU + 12.0 * _U) + 2.0 * e_pt + e_n + 4.0 * sh
        if g >= -e_g:
            lo = min(lo, n - e_n - sh)
        if g >= e_g:
            hi = min(hi, n + e_n + sh)
    if cone.whole:
        return lo, hi
    for b in range(2):
        wx, wy, e_w = (cone.w0x, cone.w0y, cone.e_w0) if b == 0 else (cone.w1x, cone.w1y, cone.e_w1)
        den = wx * dy - wy * dx
        e_den = (2.0 * e_w + 12.0 * _U) * (abs(dx) + abs(dy)) + 8.0 * _ETA
        if not abs(den) > 2.0 * e_den:  # ill-conditioned: the edge runs along the ray
            lo = min(lo, edge.seg - sh)
            continue
        q = abs(den) - e_den
        for side in range(2):  # the backward apex (lower bound), then the forward one (upper bound)
            o = -sh if side == 0 else sh
            bx, by = ax - o * ux, ay - o * uy  # a relative to the apex
            e_o = 4.0 * _U * (abs(ax) + abs(ay)) + sh * (2.0 * e_u + 4.0 * _U)
            cross = bx * dy - by * dx
            e_cross = 12.0 * _U * (abs(bx * dy) + abs(by * dx)) + e_o * (abs(dx) + abs(dy)) + 8.0 * _ETA
            snum = wy * bx - wx * by
            e_snum = (2.0 * e_w + 12.0 * _U) * (abs(bx) + abs(by)) + 2.0 * e_o + 8.0 * _ETA
            r, sp = cross / den, snum / den
            e_r = 2.0 * ((abs(r) * e_den * (1.0 + 8.0 * _U) + e_cross) / q + 4.0 * _U * abs(r) + _ETA)
            e_s = 2.0 * ((abs(sp) * e_den * (1.0 + 8.0 * _U) + e_snum) / q + 4.0 * _U * abs(sp) + _ETA)
            if side == 1:
                if r >= e_r and sp >= e_s and sp <= 1.0 - e_s:
                    hi = min(hi, r + e_r)
            elif r >= -e_r and sp >= -e_s and sp <= 1.0 + e_s:
                lo = min(lo, max(r - e_r, 0.0))
    return lo, hi


@njit
def sector_bounds_kernel(x: float, y: float, th: float, alpha: np.ndarray, gamma: np.ndarray,
                         edges: np.ndarray, bbox: np.ndarray, reach: float, perr: float,
                         out: np.ndarray) -> None:  # fmt: skip
    """Rigorous bounds ``out[s] = (lo, hi)``, ``lo <= d_s <= hi``, of the true distance ``d_s`` from the true
    position to the nearest obstacle point of sector ``s`` (thesis Eq. 4.22), written in place.

    The true heading is ``th`` exactly (:mod:`.arc_jit`); the true position lies within ``perr`` of ``(x, y)``
    in each coordinate (the simulator's accumulated bound). Three effects are bounded:

    * **The pose error.** A cone is not Lipschitz in its apex (an obstacle corner on a boundary ray enters
      or leaves it), so the apex is moved instead: with ``σ = δ / sin γ``, every point of the true cone lies
      in the cone of apex ``p − σ u`` (its boundary lines lie ``σ sin γ = δ`` outside, for any ``γ < π``,
      convex or not), and every point of the cone of apex ``p + σ u`` lies in the true cone. So ``lo`` is
      the lower bound from the backward apex minus its distance to the truth, and ``hi`` the upper bound
      from the forward apex plus that distance. ``δ`` covers ``perr`` and the rounding of the apexes. The
      whole plane (``γ = π``) is 1-Lipschitz: ``d ± δ``. (``perr`` bounds each coordinate, so the truth
      lies within ``√2 perr < 1.5 perr``.)
    * **Rounding of the geometry** (:func:`_edge_cone`): each candidate (endpoints, foot, boundary-ray
      crossings) carries its error bound; a lower bound keeps every candidate that may lie in the cone, an
      upper bound only those proved inside it. A crossing whose denominator is not above twice its error
      (an edge along the ray) gives the whole edge's distance to the lower bound and nothing to the upper.
    * **Edges left out** by the bounding-box pre-filter lie farther than ``reach`` from ``(x, y)``:
      ``lo`` never exceeds what that proves.

    ``hi`` is ``inf`` where no obstacle point is proved inside the cone; ``lo`` is ``inf`` only if
    ``reach`` is. Half-apertures must lie in ``(0, pi]``.
    """
    S, E = alpha.shape[0], edges.shape[0]
    ux, uy, cg, e_u, sh = np.empty(S), np.empty(S), np.empty(S), np.empty(S), np.empty(S)
    w = np.empty((S, 4))
    e_w = np.empty((S, 2))
    back, whole = np.empty(S), np.empty(S, dtype=np.bool_)
    lo, hi = np.empty(S), np.empty(S)
    mag = abs(x) + abs(y)
    shift_max = 0.0
    for s in range(S):
        a = th + alpha[s]
        ux[s], uy[s], cg[s] = math.cos(a), math.sin(a), math.cos(gamma[s])
        e_u[s] = 2.0 * _U * abs(a) + _ETA + _LU
        for b in range(2):
            c = a - gamma[s] if b == 0 else a + gamma[s]
            w[s, 2 * b], w[s, 2 * b + 1] = math.cos(c), math.sin(c)
            e_w[s, b] = 2.0 * _U * (abs(a) + abs(c)) + 2.0 * _ETA + _LU
        whole[s] = gamma[s] >= math.pi
        base = 1.5 * perr + 4.0 * _U * mag + 4.0 * _ETA  # perr is per coordinate: sqrt(2) perr away
        sh[s] = 0.0
        if not whole[s]:
            sg = math.sin(gamma[s]) - _LU - 2.0 * e_u[s] - 4.0 * _U
            sh[s] = base / sg * (1.0 + 16.0 * _U) if sg > 0.0 else math.inf
        if math.isfinite(sh[s]):
            shift_max = max(shift_max, sh[s])
        back[s] = (base + sh[s] * (1.0 + 2.0 * e_u[s] + 4.0 * _U)) * (1.0 + 16.0 * _U)
        lo[s], hi[s] = math.inf, math.inf
    r2 = reach + shift_max
    reach2 = r2 * r2 * (1.0 + 16.0 * _U)
    px, py, pn, pe = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for k in range(E):
        if not edge_near(bbox, k, x, y, reach2):
            continue
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        dx, dy = edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]
        size = abs(ax) + abs(ay) + abs(dx) + abs(dy)
        e_pt = 16.0 * _U * (size + mag) + 16.0 * _ETA  # a computed point against an exact edge point
        px[0], py[0] = ax, ay
        px[1], py[1] = edges[k, 2] - x, edges[k, 3] - y
        dd = dx * dx + dy * dy
        npts = 2
        if dd > 0.0:
            t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
            px[2], py[2] = ax + t * dx, ay + t * dy
            npts = 3
        seg = math.inf
        for j in range(npts):
            pn[j] = math.hypot(px[j], py[j])
            pe[j] = e_pt + 4.0 * _LU * pn[j]
            seg = min(seg, pn[j] - pe[j])
        near = seg - shift_max * (1.0 + 16.0 * _U)  # no apex is nearer to any point of the edge
        edge = _Edge(ax, ay, dx, dy, npts, seg, e_pt)
        for s in range(S):
            if not math.isfinite(back[s]) or (near >= lo[s] and near >= hi[s]):
                continue
            cone = _ConeBounds(ux[s], uy[s], cg[s], w[s, 0], w[s, 1], w[s, 2], w[s, 3], e_u[s], e_w[s, 0],
                               e_w[s, 1], sh[s], whole[s])  # fmt: skip
            d_lo, d_hi = _edge_cone(edge, px, py, pn, pe, cone)
            lo[s], hi[s] = min(lo[s], d_lo), min(hi[s], d_hi)
    cap = reach * (1.0 - 16.0 * _U) - 1.5 * perr - 4.0 * _U * mag
    for s in range(S):
        if not math.isfinite(back[s]):
            out[s, 0], out[s, 1] = 0.0, math.inf
            continue
        out[s, 0] = max(min(sub_dn(lo[s], back[s]), cap), 0.0)
        out[s, 1] = add_up(hi[s], back[s])


@njit
def sense_kernel(pose: np.ndarray, cones: np.ndarray, edges: np.ndarray, bbox: np.ndarray, reach: float,
                 perr: float, dist: np.ndarray, bounds: np.ndarray) -> None:  # fmt: skip
    """:func:`sector_kernel` and :func:`sector_bounds_kernel` in one pass over the edges, written in place.

    ``cones`` is ``(3, S)``: the directions ``alpha``, half-apertures ``gamma`` and maximum ranges ``r_max``
    of the sectors. ``dist`` is what :func:`sector_kernel` writes with ``cut = r_max`` and ``reach`` (the
    witnesses are not kept), ``bounds`` what :func:`sector_bounds_kernel` writes with the reach
    ``reach * (1 + 1e-9) + 1e-9`` and ``perr`` (as :meth:`.sensors.SensorSuite.true_ranges` and
    :meth:`.sensors.SensorSuite.range_bounds` call them): the same floating-point operations on the same
    values, bit for bit, sharing the cone directions and boundary rays, the edges' pre-filter and the
    candidate points the two kernels compute alike (``tests/envs/sim/test_sense.py`` checks it). ``pose`` is
    ``(x, y, theta)``.
    """
    x, y, th = pose[0], pose[1], pose[2]
    S, E = cones.shape[1], edges.shape[0]
    # the cones: sector_kernel's directions and rays are sector_bounds_kernel's (the same expressions)
    work = np.empty((8, S))  # one allocation for the per-cone values
    ux, uy, cg, e_u, sh, back, lo, hi = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7]
    w = np.empty((S, 4))
    e_w = np.empty((S, 2))
    whole = np.empty(S, dtype=np.bool_)
    mag = abs(x) + abs(y)
    shift_max = 0.0
    for s in range(S):
        gamma = cones[1, s]
        a = th + cones[0, s]
        ux[s], uy[s], cg[s] = math.cos(a), math.sin(a), math.cos(gamma)
        e_u[s] = 2.0 * _U * abs(a) + _ETA + _LU
        for b in range(2):
            c = a - gamma if b == 0 else a + gamma
            w[s, 2 * b], w[s, 2 * b + 1] = math.cos(c), math.sin(c)
            e_w[s, b] = 2.0 * _U * (abs(a) + abs(c)) + 2.0 * _ETA + _LU
        whole[s] = gamma >= math.pi
        base = 1.5 * perr + 4.0 * _U * mag + 4.0 * _ETA
        sh[s] = 0.0
        if not whole[s]:
            sg = math.sin(gamma) - _LU - 2.0 * e_u[s] - 4.0 * _U
            sh[s] = base / sg * (1.0 + 16.0 * _U) if sg > 0.0 else math.inf
        if math.isfinite(sh[s]):
            shift_max = max(shift_max, sh[s])
        back[s] = (base + sh[s] * (1.0 + 2.0 * e_u[s] + 4.0 * _U)) * (1.0 + 16.0 * _U)
        lo[s], hi[s] = math.inf, math.inf
        dist[s] = _INF
    reach_t2 = reach * reach  # sector_kernel's pre-filter
    reach_b = reach * (1.0 + 1e-9) + 1e-9  # range_bounds' reach
    r2 = reach_b + shift_max
    reach2 = r2 * r2 * (1.0 + 16.0 * _U)
    pts = np.empty((7, 3))  # sector_kernel's candidates and their norms, then sector_bounds_kernel's
    tx, ty, tn, px, py, pn, pe = pts[0], pts[1], pts[2], pts[3], pts[4], pts[5], pts[6]
    for k in range(E):
        # edge_near's test against both reaches (reach2 >= reach_t2): one distance, two comparisons
        bx = max(max(bbox[k, 0] - x, x - bbox[k, 2]), 0.0)
        by = max(max(bbox[k, 1] - y, y - bbox[k, 3]), 0.0)
        bd2 = bx * bx + by * by
        keep_t, keep_b = bd2 <= reach_t2, bd2 <= reach2
        if not (keep_t or keep_b):
            continue
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        dx, dy = edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]
        dd = dx * dx + dy * dy
        npts = 2
        fx = fy = fn = 0.0
        if dd > 0.0:  # the foot: the same expression in both kernels
            t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
            fx, fy = ax + t * dx, ay + t * dy
            fn = math.hypot(fx, fy)
            npts = 3
        an = math.hypot(ax, ay)
        if keep_t:
            tx[0], ty[0], tx[1], ty[1] = ax, ay, ax + dx, ay + dy
            tn[0], tn[1] = an, math.hypot(tx[1], ty[1])
            tx[2], ty[2], tn[2] = fx, fy, fn
            near_t = npts - 1
            if npts == 2 and tn[1] < tn[0]:
                near_t = 1
            cross = ax * dy - ay * dx
            for s in range(S):
                if tn[near_t] >= dist[s]:
                    continue
                if cones[1, s] >= math.pi:  # the whole plane
                    dist[s] = tn[near_t]
                    continue
                for j in range(npts):
                    nj = tn[j]
                    if nj < dist[s] and ux[s] * tx[j] + uy[s] * ty[j] >= nj * cg[s]:
                        dist[s] = nj
                for b in range(2):
                    wxb, wyb = w[s, 2 * b], w[s, 2 * b + 1]
                    den = wxb * dy - wyb * dx
                    if den == 0.0:
                        continue
                    r = cross / den
                    sp = (wyb * ax - wxb * ay) / den
                    if r >= 0.0 and sp >= 0.0 and sp <= 1.0 and r < dist[s]:
                        dist[s] = r
        if not keep_b:
            continue
        size = abs(ax) + abs(ay) + abs(dx) + abs(dy)
        e_pt = 16.0 * _U * (size + mag) + 16.0 * _ETA
        px[0], py[0], pn[0] = ax, ay, an
        px[1], py[1] = edges[k, 2] - x, edges[k, 3] - y
        pn[1] = math.hypot(px[1], py[1])
        px[2], py[2], pn[2] = fx, fy, fn
        seg = math.inf
        for j in range(npts):
            pe[j] = e_pt + 4.0 * _LU * pn[j]
            seg = min(seg, pn[j] - pe[j])
        near = seg - shift_max * (1.0 + 16.0 * _U)
        edge = _Edge(ax, ay, dx, dy, npts, seg, e_pt)
        for s in range(S):
            if not math.isfinite(back[s]) or (near >= lo[s] and near >= hi[s]):
                continue
            cone = _ConeBounds(ux[s], uy[s], cg[s], w[s, 0], w[s, 1], w[s, 2], w[s, 3], e_u[s], e_w[s, 0],
                               e_w[s, 1], sh[s], whole[s])  # fmt: skip
            d_lo, d_hi = _edge_cone(edge, px, py, pn, pe, cone)
            lo[s], hi[s] = min(lo[s], d_lo), min(hi[s], d_hi)
    cap = reach_b * (1.0 - 16.0 * _U) - 1.5 * perr - 4.0 * _U * mag
    for s in range(S):
        if not dist[s] <= cones[2, s]:
            dist[s] = _INF
        if not math.isfinite(back[s]):
            bounds[s, 0], bounds[s, 1] = 0.0, math.inf
            continue
        bounds[s, 0] = max(min(sub_dn(lo[s], back[s]), cap), 0.0)
        bounds[s, 1] = add_up(hi[s], back[s])


__all__ = [
    "edge_boxes",
    "edge_near",
    "points_edges_kernel",
    "sector_bounds_kernel",
    "sector_kernel",
    "segment_distance",
    "sense_kernel",
]
