"""codac's contractor and separator tests re-expressed: ``CtcInverse`` (our :class:`CtcFwdBwd`),
``SepInverse``, ``SepTransform``, ``SepProj``, ``CtcSegment`` (our :class:`CtcSegments`), ``CtcPolygon``
(our :class:`CtcPolygonBoundary`), ``SepPolygon``, ``SepQInter`` (ibex's ``qinter`` test), the
ParabolasExample of ``CtcInverse`` (judged on the hull of its one connected subset) and ``CtcPolar`` at
``ρ = 0``.

The truth of a contracted box (or of a separator's outer part) is the hull of the box's points in the
set, of its inner part the hull of the points outside it; both are taken here over a grid of the box
plus the set's known extreme points, membership decided at 200 bits (:func:`judge.sampled_hull`). A
sampled hull lies inside the true one, so the soundness check is a necessary condition, exact where the
extreme points are listed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import mpmath
import numpy as np
import pytest
from judge import EMPTY, box_of, judge_box, sampled_hull

from digslam.observer import Box, CtcFwdBwd, Function, Interval, SepInverse, SepProj, SepQInter, pave, sqr
from digslam.observer.polar import CtcPolar
from digslam.observer.sets import CtcFixPoint, SepBox, SepCtcPair
from digslam.observer.sets.sep_polygon import CtcSegments, SepPolygon
from digslam.observer.sets.transforms import SepTransform, Transform

oo = math.inf
CASES: list[tuple[str, Callable[[], Any], Any, Callable[[], Any], float]] = []


def case(name: str, ours: Callable[[], Any], peer: Any, truth: Callable[[], Any], tol: float = 0.0) -> None:
    CASES.append((f"{name}#{len(CASES)}", ours, peer, truth, tol))


def ctc_case(name: str, ctc: Any, box: list[tuple[float, float]], peer: Any, member: Callable[..., bool],
             tol: float = 0.0, extra: tuple[Any, ...] = ()) -> None:  # fmt: skip
    case(name, lambda: box_of(ctc(Box(box))), peer, lambda: sampled_hull(box, member, extra=extra), tol)


def sep_case(name: str, sep: Any, box: list[tuple[float, float]], peer_in: Any, peer_out: Any,
             member: Callable[..., bool], tol: float = 0.0, extra: tuple[Any, ...] = ()) -> None:  # fmt: skip
    def ours() -> Any:
        xin, xout = sep(Box(box))
        return box_of(xout), box_of(xin)

    def truth() -> Any:
        return (sampled_hull(box, member, extra=extra),
                sampled_hull(box, lambda *p: not member(*p), extra=extra))  # fmt: skip

    case(name, ours, (peer_out, peer_in), truth, tol)


R2 = [(-oo, oo), (-oo, oo)]
# CtcInverse_1 and _2: x0 - x1 = 0 (codac's scalar and vector forms)
diag = lambda a, b: a == b  # noqa: E731
for vec in (False, True):
    f = Function(lambda x: x[0] - x[1], n=2)
    c = CtcFwdBwd(f, Box([(0, 0)]) if vec else Interval(0))
    for box, peer in ((R2, R2), ([(1, 2), (1, 2)], [(1, 2), (1, 2)]), ([(1, oo), (1, oo)], [(1, oo), (1, oo)]),
                      ([(10, 10), (10, 10)], [(10, 10), (10, 10)]), ([(1, 5), (8, 9)], [EMPTY, EMPTY])):  # fmt: skip
        ends = [(t, t) for t in (1, 2, 5, 10, -1e3, 1e3) if all(lo <= t <= hi for lo, hi in box)]
        ctc_case("CtcInverse_diag", c, box, peer, diag, extra=tuple(ends))


def ellipse(a: Any, b: Any) -> bool:  # x0 >= 0 and (x0/7)² + (x1/3)² = 1 (CtcInverse_3)
    return a >= 0 and (a / 7) ** 2 + (b / 3) ** 2 == 1


def _ellipse_pts(box: list[tuple[float, float]]) -> tuple[Any, ...]:
    """Points of the ellipse on the box's sides (exact hull ends of the contraction)."""
    pts = []
    with mpmath.workprec(200):
        for a in (box[0][0], box[0][1]):
            r = 1 - (mpmath.mpf(a) / 7) ** 2
            if r >= 0:
                pts += [(mpmath.mpf(a), 3 * mpmath.sqrt(r)), (mpmath.mpf(a), -3 * mpmath.sqrt(r))]
        for b in (box[1][0], box[1][1]):
            r = 1 - (mpmath.mpf(b) / 3) ** 2
            if r >= 0:
                pts += [(7 * mpmath.sqrt(r), mpmath.mpf(b))]
    return tuple(pts)


def _on_ellipse(tol: float) -> Callable[..., bool]:
    return lambda a, b: a >= 0 and abs((a / 7) ** 2 + (b / 3) ** 2 - 1) <= tol


f3 = Function(lambda x: [x[0], sqr(x[0] / 7.0) + sqr(x[1] / 3.0)], n=2)
for centred in (False, True):
    c3 = CtcFwdBwd(f3, Box([(0, oo), (1, 1)]), centred=centred)
    for box, peer, tol in (([(0, 0.8), (-2.28, -1.56)], [EMPTY, EMPTY], 0.0),
                           ([(4, 5.4), (-0.05, 2.45)], [(4.0397, 5.40), (1.9089, 2.45)], 1e-2),
                           ([(6.25, 6.7), (0.9, 1.85)], [(6.25, 6.67), (0.9, 1.351)], 1e-2),
                           ([(-6, -5), (0, 2)], [EMPTY, EMPTY], 0.0), ([(2, 3), (-1, 1)], [EMPTY, EMPTY], 0.0)):  # fmt: skip
        ctc_case(
            f"CtcInverse_3{'c' if centred else ''}", c3, box, peer, _on_ellipse(0.0), tol, _ellipse_pts(box)
        )

# issue 245: SepInverse / CtcInverse of x0² + x1² - 1 = 0 on R²
circle = Function(lambda s: sqr(s[0]) + sqr(s[1]) - 1.0, n=2)
on_circle = lambda a, b: a * a + b * b == 1  # noqa: E731
CIRCLE_PTS = ((1, 0), (-1, 0), (0, 1), (0, -1))
for y0 in (
    Interval(0),
    Box([(0, 0)]),
    0.0,
    0,
    Interval(0.0, 0.0),
    Box([(0.0, 0.0)]),
):  # codac's six spellings
    ctc_case(
        "CtcInverse_issue245", CtcFwdBwd(circle, y0), R2, [(-1, 1), (-1, 1)], on_circle, extra=CIRCLE_PTS
    )
    sep_case(
        "SepInverse_issue245", SepInverse(circle, y0), R2, R2, [(-1, 1), (-1, 1)], on_circle, extra=CIRCLE_PTS
    )

# tests_SepInverse: (x0, (x0/7)² + (x1/3)²) ∈ [0, oo] × [-oo, 1]
in_half_ellipse = lambda a, b: a >= 0 and (a / 7) ** 2 + (b / 3) ** 2 <= 1  # noqa: E731
for centred in (False, True):
    s = SepInverse(f3, Box([(0, oo), (-oo, 1)]), centred=centred)
    tag = "c" if centred else ""
    for box, pin, pout, tol in (
        ([(0, 0.8), (-2.28, -1.56)], [(0, 0), (-2.28, -1.56)], [(0, 0.8), (-2.28, -1.56)], 0.0),
        ([(4, 5.4), (-0.05, 2.45)], [(4.039, 5.40), (1.908, 2.45)], [(4, 5.4), (-0.05, 2.45)], 1e-2),
        ([(6.25, 6.7), (0.9, 1.85)], [(6.25, 6.70), (0.9, 1.85)], [(6.25, 6.7), (0.9, 1.85)], 1e-2),
        ([(-6, -5), (0, 2)], [(-6, -5), (0, 2)], [EMPTY, EMPTY], 0.0),
        ([(2, 3), (-1, 1)], [EMPTY, EMPTY], [(2, 3), (-1, 1)], 0.0),
    ):
        sep_case(f"SepInverse{tag}", s, box, pin, pout, in_half_ellipse, tol, _ellipse_pts(box))

# tests_SepInverse_other_test: the unit disk
disk = lambda a, b: a * a + b * b <= 1  # noqa: E731
for centred in (False, True):
    s = SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]), n=2), Interval(0, 1), centred=centred)
    for box, pin, pout in (([(0.1, 0.2), (0.1, 0.2)], [EMPTY, EMPTY], [(0.1, 0.2), (0.1, 0.2)]),
                           ([(-0.2, 0.2), (-0.2, 0.2)], [EMPTY, EMPTY], [(-0.2, 0.2), (-0.2, 0.2)]),
                           (R2, R2, [(-1, 1), (-1, 1)])):  # fmt: skip
        sep_case(f"SepInverse_disk{'c' if centred else ''}", s, box, pin, pout, disk, extra=CIRCLE_PTS)

# SepTransform: the unit disk moved to (-2, -2)
shift = Transform(
    Function(lambda x: [x[0] - 2.0, x[1] - 2.0], n=2), Function(lambda x: [x[0] + 2.0, x[1] + 2.0], n=2)
)
moved = lambda a, b: (a + 2) ** 2 + (b + 2) ** 2 <= 1  # noqa: E731
MOVED_PTS = (
    (-1, -2),
    (-3, -2),
    (-2, -1),
    (-2, -3),
    (-2.5, -2 + math.sqrt(0.75)),
    (-1.5, -2 + math.sqrt(0.75)),
)
for centred in (False, True):
    st = SepTransform(SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]), n=2), Interval(0, 1), centred=centred),
                      shift)  # fmt: skip
    tag = "c" if centred else ""
    sep_case(f"SepTransform{tag}", st, R2, R2, [(-3, -1), (-3, -1)], moved, 1e-1, MOVED_PTS)
    sep_case(f"SepTransform{tag}", st, [(-2.2, -1.8), (-2.2, -1.8)], [EMPTY, EMPTY], [(-2.2, -1.8), (-2.2, -1.8)],
             moved, 0.0, MOVED_PTS)  # fmt: skip
    sep_case(f"SepTransform{tag}", st, [(-2.5, -1.5), (-2, 10)], [(-2.5, -1.5), (-1.134, 10)],
             [(-2.5, -1.5), (-2, -1)], moved, 1e-1, MOVED_PTS)  # fmt: skip


# SepProj: the ellipsoidal shell 0.7 <= f <= 1 projected along x2 ∈ [0.1, 0.2]
def shell_proj(a: Any, b: Any) -> bool:
    """Some x2 ∈ [0.1, 0.2] puts (a, b, x2) in the shell: f is a convex quadratic in x2, so its range over
    [0.1, 0.2] is [min, max] with the min at the clipped vertex -a/2, the max at an end."""
    g = lambda z: 2 * a * a + a * b + a * z + b * b + z * z  # noqa: E731
    lo_z, hi_z = mpmath.mpf("0.1"), mpmath.mpf("0.2")
    zv = min(max(-a / 2, lo_z), hi_z)
    fmin, fmax = g(zv), max(g(lo_z), g(hi_z))
    return fmin <= 1 and fmax >= mpmath.mpf("0.7")


def _shell_sep(centred: bool) -> SepInverse:
    f = Function(lambda x: 2 * sqr(x[0]) + x[0] * x[1] + x[0] * x[2] + sqr(x[1]) + sqr(x[2]), n=3)
    return SepInverse(f, Interval(0.7, 1), centred=centred)


for centred in (False, True):
    tag = "c" if centred else ""
    sp = SepProj(_shell_sep(centred), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=True)
    case(f"SepProj{tag}", (lambda sp=sp: tuple(box_of(p) for p in sp(Box([(0.2, 0.4), (0.0, 1.0)])))[::-1]),
         ([(0.2, 0.4), (0, 0.94)], [(0.2, 0.4), (0.0, 1.0)]),
         lambda: (sampled_hull([(0.2, 0.4), (0.0, 1.0)], shell_proj, k=81),
                  sampled_hull([(0.2, 0.4), (0.0, 1.0)], lambda a, b: not shell_proj(a, b), k=81)), 1e-2)  # fmt: skip
    case(f"SepProj{tag}", (lambda sp=sp: tuple(box_of(p) for p in sp(Box([(-0.4, -0.2), (0.95, 1.5)])))[::-1]),
         ([(-0.4, -0.2), (0.95, 1.15)], [(-0.4, -0.2), (0.95, 1.5)]),
         lambda: (sampled_hull([(-0.4, -0.2), (0.95, 1.5)], shell_proj, k=81),
                  sampled_hull([(-0.4, -0.2), (0.95, 1.5)], lambda a, b: not shell_proj(a, b), k=81)), 1e-2)  # fmt: skip
    case(f"SepProj{tag}", (lambda sp=sp: tuple(box_of(p) for p in sp(Box([(0.65, 0.65), (-0.5, -0.4)])))[::-1]),
         ([(0.65, 0.65), (-0.5, -0.4)], [EMPTY, EMPTY]),
         lambda: (sampled_hull([(0.65, 0.65), (-0.5, -0.4)], shell_proj),
                  sampled_hull([(0.65, 0.65), (-0.5, -0.4)], lambda a, b: not shell_proj(a, b))), 0.0)  # fmt: skip


# CtcSegment
def on_segment(a: Any, b: Any, p: Any, q: Any) -> bool:
    (ax, ay), (bx, by) = a, b
    cross = (bx - ax) * (q - ay) - (by - ay) * (p - ax)
    return cross == 0 and min(ax, bx) <= p <= max(ax, bx) and min(ay, by) <= q <= max(ay, by)


for a, b, box, peer in (
    ((3, -1), (3, 4), R2, [(3, 3), (-1, 4)]), ((3, -1), (3, 4), [(3.0, 3.16), (2.5, 3.2)], [(3, 3), (2.5, 3.2)]),
    ((3, -1), (3, 4), [(3.02, 3.16), (2.5, 3.2)], [EMPTY, EMPTY]), ((-1, -1), (1, 1), R2, [(-1, 1), (-1, 1)]),
    ((-1, -1), (1, 1), [(-oo, oo), (0, 0)], [(0, 0), (0, 0)]), ((-1, -1), (1, 1), [(0, oo), (0, oo)], [(0, 1), (0, 1)]),
    ((-1, -1), (1, 1), [(2, oo), (2, oo)], [EMPTY, EMPTY]), ((0, 0), (10, 20), [(-5, 50), (-5, 50)], [(0, 10), (0, 20)]),
    ((0, 0), (10, 20), [(10, 50), (20, 50)], [(10, 10), (20, 20)]), ((5, 5), (5, 5), [(-5, 50), (-5, 50)], [(5, 5), (5, 5)]),
    ((5, 5), (10, 5), [(-50, 50), (-50, 50)], [(5, 10), (5, 5)]), ((-5, -5), (-5, 15), [(-50, 50), (-50, 50)], [(-5, -5), (-5, 15)]),
    ((0, 0), (10, 20), [(-5, -2), (-5, 50)], [EMPTY, EMPTY]), ((0, 0), (10, 20), R2, [(0, 10), (0, 20)]),
):  # fmt: skip
    ctc_case("CtcSegment", CtcSegments([a], [b]), box, peer, lambda p, q, a=a, b=b: on_segment(a, b, p, q),
             extra=(a, b) + tuple((t, t) for t in (0,) if a == (-1, -1)))  # fmt: skip


# CtcPolygon / SepPolygon: codac's polygons (the second with a hole)
def inside(rings: list[list[tuple[float, float]]], p: Any, q: Any) -> bool:
    """Even-odd rule at 200 bits (boundary points count as inside: the closed polygon)."""
    c = False
    for ring in rings:
        for (ax, ay), (bx, by) in zip(ring, ring[1:] + ring[:1]):
            if on_segment((ax, ay), (bx, by), p, q):
                return True
            if (ay > q) != (by > q) and p < ax + (bx - ax) * (q - ay) / mpmath.mpf(by - ay):
                c = not c
    return c


def on_boundary(rings: list[list[tuple[float, float]]], p: Any, q: Any) -> bool:
    return any(on_segment(a, b, p, q) for ring in rings for a, b in zip(ring, ring[1:] + ring[:1]))


P1 = [[(3, -1), (3, 4), (5, 6), (-1, 1)]]
P2 = [[(6, -6), (7, 9), (0, 5), (-9, 8), (-8, -9)], [(-2, 3), (3.5, 2), (1.5, 0.5), (3, -4), (-3, -3)]]
P3 = [[(6, -6), (7, 9), (0, 5), (-9, 8), (-8, -9)]]
infl = lambda x, y: [(x - 0.5, x + 0.5), (y - 0.5, y + 0.5)]  # noqa: E731
for rings, box, pin, pout in (
    (P1, R2, R2, [(-1, 5), (-1, 6)]), (P1, [(3.02, 3.16), (2.5, 3.2)], [(3.02, 3.16), (2.5, 3.2)], [EMPTY, EMPTY]),
    (P2, infl(0, 0), infl(0, 0), [EMPTY, EMPTY]), (P2, infl(5, -5), [EMPTY, EMPTY], infl(5, -5)),
    (P2, infl(-1, 8), infl(-1, 8), [EMPTY, EMPTY]), (P3, infl(5, -5), [EMPTY, EMPTY], infl(5, -5)),
    (P3, infl(-1, 8), infl(-1, 8), [EMPTY, EMPTY]),
):  # fmt: skip
    verts = tuple(v for r in rings for v in r)
    sep_case("SepPolygon", SepPolygon([np.array(r, dtype=float) for r in rings]), box, pin, pout,
             lambda p, q, rings=rings: inside(rings, p, q), extra=verts)  # fmt: skip
    # CtcPolygon = the outer part of SepPolygon (codac's CtcPolygon contracts onto the closed polygon)
    ctc_case("CtcPolygon", lambda b, rings=rings: SepPolygon([np.array(r, dtype=float) for r in rings])(b)[1],
             box, pout, lambda p, q, rings=rings: inside(rings, p, q), extra=verts)  # fmt: skip


# SepQInter: codac's test only builds SepQInter(1, s1, s2) of x ↦ x in [-1, 1] and in [5, 6]; the peer
# value here is the minimal answer on each box (the q-relaxed intersection of two exact separators)
s1 = SepInverse(Function(lambda v: v[0], n=1), Box([(-1, 1)]))
s2 = SepInverse(Function(lambda v: v[0], n=1), Box([(5, 6)]))
ENDS = ((-1,), (1,), (5,), (6,))


def _closure_hull(box: tuple[float, float], pieces: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Hull of the closures of the non-empty ``box ∩ (a, b)`` (open pieces), exactly."""
    met = [(max(box[0], a), min(box[1], b)) for a, b in pieces if max(box[0], a) < min(box[1], b)]
    return [(min(a for a, _ in met), max(b for _, b in met))] if met else [EMPTY]


SETS = {1: ([(-1, 1), (5, 6)], [(-oo, -1), (1, 5), (6, oo)]), 0: ([], [(-oo, oo)])}
for q, member in ((1, lambda t: -1 <= t <= 1 or 5 <= t <= 6), (0, lambda t: False)):
    for box in ([(-2, 7)], [(0, 3)], [(2, 4)], [(0.5, 5.5)], [(-0.5, 0.5)], [(5, 6)]):
        ins, outs = SETS[q]
        met = [
            (max(box[0][0], a), min(box[0][1], b)) for a, b in ins if max(box[0][0], a) <= min(box[0][1], b)
        ]
        pout = [(min(a for a, _ in met), max(b for _, b in met))] if met else [EMPTY]
        sep_case(f"SepQInter_q{q}", SepQInter([s1, s2], q), box, _closure_hull(box[0], outs), pout, member, 0.0,
                 ENDS)  # fmt: skip


# ibex's qinter test (codac 1, tests_sep_qinterprojf.cpp): five boxes, the points in at least `need` of them.
# SepQInter's q counts the sets a point may miss (q = 5 - need); the outer part on a frame holding the five
# boxes is their box q-intersection: ibex's exact `qinter` (SepQInter's default) or its coordinate-wise
# `qinter_projf` (exact=False); the inner part is the frame (its corners lie outside the set).
QBOXES = [
    [(1, 5), (1, 6)],
    [(3, 7), (2, 5.5)],
    [(1.5, 2.5), (4.5, 8)],
    [(2.5, 5), (0, 4)],
    [(1.5, 8), (1.5, 3)],
]
QFRAME = [(0, 9), (-1, 9)]
QINTER = {1: [(1, 8), (0, 8)], 2: [(1.5, 7), (1, 6)], 3: [(2.5, 5), (1.5, 4)], 4: [(3, 5), (2, 3)]}
QPROJF = {1: [(1, 8), (0, 8)], 2: [(1.5, 7), (1, 6)], 3: [(1.5, 5), (1.5, 5.5)], 4: [(2.5, 5), (2, 3)]}
QCORNERS = tuple((a, b) for a in sorted({v for bx in QBOXES for v in bx[0]})
                 for b in sorted({v for bx in QBOXES for v in bx[1]}))  # fmt: skip


def _in_boxes(need: int) -> Callable[..., bool]:
    return lambda a, b: sum(lo <= a <= hi and c <= b <= d for (lo, hi), (c, d) in QBOXES) >= need


for exact, table in ((True, QINTER), (False, QPROJF)):
    for need, peer in table.items():
        sep = SepQInter([SepBox(Box(bx)) for bx in QBOXES], 5 - need, exact=exact)
        sep_case(f"SepQInter_{'qinter' if exact else 'projf'}{need}", sep, QFRAME, QFRAME, peer, _in_boxes(need),
                 0.0, QCORNERS)  # fmt: skip
# codac 1's SepQInterProjF test: q = 4 of the same five separators (in any one box), on [2, 4] × [3, 5]
for exact in (True, False):
    sep_case("SepQInter_projf_sep", SepQInter([SepBox(Box(bx)) for bx in QBOXES], 4, exact=exact),
             [(2, 4), (3, 5)], [EMPTY, EMPTY], [(2, 4), (3, 5)], _in_boxes(1), 0.0, QCORNERS)  # fmt: skip


# ParabolasExample (codac2_tests_CtcInverse): two Bézier patches meet along a curve; CtcInverse of their
# difference = 0 paved at 0.01 leaves one connected subset. The first patch is z = x - x²/2 over
# (x, y) = (2a0, 2a1), the second z = c0 - 2 (c0 - c1) s (1 - s) over (x, y) = (2a3, 2a2) with c0, c1 the
# doubles 0.55 and -0.45: the curve is a0 = a3 = u, a1 = a2 = w with 2u(1 - u) = c0 - 2(c0 - c1) w(1 - w),
# inside [0.05, 0.18]² on (u, w); its hull is [u*, 0.18]⁴, u* the u at w = 0.18.
PARAB_P = (((0, 0, 0), (1, 0, 1), (2, 0, 0)), ((0, 2, 0), (1, 2, 1), (2, 2, 0)))
PARAB_Q = (((0, 0, 0.55), (0, 1, -0.45), (0, 2, 0.55)), ((2, 0, 0.55), (2, 1, -0.45), (2, 2, 0.55)))
PARAB_X0 = [(0, 1), (0, 1), (0.05, 0.18), (0.05, 0.18)]
PARAB_PEER = [(0.149199, 0.182388), (0.148306, 0.1826), (0.148054, 0.18), (0.148732, 0.18)]


def _patch(u: Any, v: Any, pts: Any) -> list[Any]:
    def bez(row: Any, k: int) -> Any:
        return sqr(1 - u) * row[0][k] + 2 * u * (1 - u) * row[1][k] + sqr(u) * row[2][k]

    return [(1 - v) * bez(pts[0], k) + v * bez(pts[1], k) for k in range(3)]


def _parab_h(a: Any) -> list[Any]:
    p, q = _patch(a[0], a[1], PARAB_P), _patch(a[2], a[3], PARAB_Q)
    return [p[k] - q[k] for k in range(3)]


def _parab_truth() -> list[tuple[Any, Any]]:
    with mpmath.workprec(200):
        c0, c1, top = mpmath.mpf(0.55), mpmath.mpf(-0.45), mpmath.mpf(0.18)
        rhs = c0 - 2 * (c0 - c1) * top * (1 - top)  # 2u(1 - u) at w = 0.18 (the smallest)
        u_min = (1 - mpmath.sqrt(1 - 2 * rhs)) / 2
        return [(u_min, top)] * 4


def _parab_ours(ctc: Any) -> Any:
    subsets = pave(Box(PARAB_X0), SepCtcPair(None, ctc), 0.01, ratio=0.49).connected_subsets()
    assert len(subsets) == 1, f"{len(subsets)} connected subsets (codac: 1)"
    (lo, hi) = subsets[0]
    return [(float(a), float(b)) for a, b in zip(lo.min(axis=0), hi.max(axis=0))]


PARAB_F = Function(_parab_h, n=4)
# natural form: HC4 to a fixpoint; centred form: one pass, as codac's CtcInverse
for centred in (False, True):
    c = CtcFwdBwd(PARAB_F, Box([(0, 0)] * 3), centred=centred)
    c = c if centred else CtcFixPoint(c, ratio=1e-3)
    case(f"CtcInverse_parabolas{'c' if centred else ''}", lambda c=c: _parab_ours(c), PARAB_PEER, _parab_truth,
         1e-4)  # fmt: skip


# CtcPolar at ρ = 0: the origin with every θ is in Π (Eq. 3.22); codac's CtcPolar (its Catan2) drops the
# origin and returns the empty box here (codac 2.0, run apart from this process)
case("CtcPolar_origin", lambda: box_of(CtcPolar()(Box([(-1, 1), (-1, 1), (0, 0), (0, 1)]))), [EMPTY] * 4,
     lambda: [(mpmath.mpf(0), mpmath.mpf(0))] * 3 + [(mpmath.mpf(0), mpmath.mpf(1))])  # fmt: skip


@pytest.mark.parametrize(("name", "ours", "peer", "truth", "tol"), CASES, ids=[c[0] for c in CASES])
def test_set_case(
    name: str, ours: Callable[[], Any], peer: Any, truth: Callable[[], Any], tol: float
) -> None:
    o, p, t = ours(), peer, truth()
    if isinstance(o, tuple):  # a separator: (outer, inner)
        judge_box(name, o[0], p[0], t[0], tol, inner=(o[1], p[1], t[1]))
    else:
        judge_box(name, o, p, t, tol)
