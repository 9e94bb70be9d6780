"""The judge of the peer suite: a 200-bit truth, the soundness check and the verdict against codac.

Every case of ``tests/peer`` holds three things: our result (float bounds), the peer's expected value as
codac's own test writes it (with the tolerance of codac's ``Approx`` when it uses one), and a truth
computed here at 200 bits with mpmath (:func:`truth` helpers: monotone end values, critical points,
corner rules). :func:`judge` asserts that our result holds the truth (soundness) and returns whether it
is *tighter*, *equal* (within the peer's tolerance or a few ulps of outward rounding) or *wider* than the
peer's value. A wider case fails unless :data:`WIDER` explains it by a design choice.

Intervals here are ``(lo, hi)`` pairs of floats (our side, the peer's side) or of mpf (the truth); the
empty interval is ``(inf, -inf)``.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

import mpmath
import numpy as np

PREC = 200
INF = math.inf
EMPTY = (INF, -INF)
#: verdicts of the cases run in this session (``conftest.py`` prints the tally)
TALLY: Counter[str] = Counter()

#: every case where our result is wider than the peer's expected value, with the design choice behind it
WIDER: dict[str, str] = {
    "SepProj#55": (
        "SepInverse runs without the centred form by default (it costs ~2x per call and the paver bisects "
        "instead, bench_paver.py); codac's SepInverse uses it by default. The same projection with "
        "SepInverse(..., centred=True) is case SepProjc#58: y <= 1.117, tighter than codac's 1.15 "
        "(truth 1.08)."
    ),
    "CtcInverse_parabolas#110": (
        "CtcFwdBwd runs the natural form by default (the centred form costs more per call, as for SepProj#55). "
        "HC4 to a fixpoint paves codac's single connected subset, but its hull is [0.1437, 0.1882] on a0 "
        "against codac's [0.1492, 0.1824], codac's CtcInverse using the centred form. With centred=True "
        "(case CtcInverse_parabolasc#111) the hull is [0.14982, 0.18024]: tighter than codac's (truth "
        "[0.149856, 0.18] on every coordinate)."
    ),
    "CtcPolar_origin#112": (
        "CtcPolar contracts onto Pi of Eq. 3.22, where the origin (x, y, rho) = 0 goes with every theta; "
        "codac's CtcPolar (its Catan2, atan2 being undefined at the origin) drops the origin and returns the "
        "empty box on [-1, 1]^2 x {0} x [0, 1]: codac's value misses the points (0, 0, 0, theta) of the set."
    ),
}


def mpf(x: Any) -> mpmath.mpf:
    with mpmath.workprec(PREC):
        return mpmath.mpf(x)


def is_empty(iv: Sequence[Any]) -> bool:
    return bool(iv[0] > iv[1])


def hull(*ivs: Sequence[Any]) -> tuple[Any, Any]:
    live = [iv for iv in ivs if not is_empty(iv)]
    if not live:
        return EMPTY
    return min(iv[0] for iv in live), max(iv[1] for iv in live)


def inter(a: Sequence[Any], b: Sequence[Any]) -> tuple[Any, Any]:
    lo, hi = max(a[0], b[0]), min(a[1], b[1])
    return (lo, hi) if lo <= hi else EMPTY


def _holds(ours: Sequence[float], truth: Sequence[Any]) -> bool:
    """``truth ⊂ ours`` compared at 200 bits."""
    if is_empty(truth):
        return True
    if is_empty(ours):
        return False
    with mpmath.workprec(PREC):
        return bool(mpf(ours[0]) <= truth[0] and truth[1] <= mpf(ours[1]))


def _compare(ours: Sequence[float], peer: Sequence[float], tol: float) -> str:
    if is_empty(ours) and is_empty(peer):
        return "equal"
    if is_empty(ours):
        return "tighter"
    if is_empty(peer):
        return "wider"

    def slack(
        b: float,
    ) -> float:  # the peer's Approx tolerance (relative beyond 1), at least 4 ulps of outward rounding
        if not math.isfinite(b):
            return 0.0
        return max(tol * max(1.0, abs(b)), 4 * math.ulp(b))

    lo, hi = float(ours[0]), float(ours[1])
    plo, phi = float(peer[0]), float(peer[1])
    if lo < plo - slack(plo) or hi > phi + slack(phi):
        return "wider"
    if lo > plo + slack(plo) or hi < phi - slack(phi):
        return "tighter"
    return "equal"


def judge_box(case: str, ours: Any, peer: Any, truth: Any, tol: float = 0.0, inner: Any = None) -> str:
    """Judge a box result (one interval per coordinate): soundness on every coordinate, then the verdict.

    ``ours``, ``peer``, ``truth`` are sequences of ``(lo, hi)``; the box is empty when any coordinate is.
    ``inner`` optionally gives ``(ours_in, peer_in, truth_in)`` of a separator's inner part, judged the
    same way (the inner part must hold the hull of the box's points outside the set).
    """
    parts = [(ours, peer, truth)] + ([inner] if inner is not None else [])
    verdicts = []
    for o, p, t in parts:
        o, p, t = _norm(o), _norm(p), _norm(t)
        for k, (oi, ti) in enumerate(zip(o, t)):
            assert _holds(oi, ti), (
                f"{case}: UNSOUND on coordinate {k}: ours {oi} does not hold the truth {ti}"
            )
        verdicts.append(_combine([_compare(oi, pi, tol) for oi, pi in zip(o, p)]))
    return record(case, _combine(verdicts), f"ours {parts[0][0]}, peer {parts[0][1]}")


def judge(case: str, ours: Any, peer: Any, truth: Any, tol: float = 0.0) -> str:
    """Judge one interval."""
    return judge_box(case, [ours], [peer], [truth], tol)


def _norm(box: Any) -> list[tuple[Any, Any]]:
    box = [tuple(iv) for iv in box]
    if any(is_empty(iv) for iv in box):
        return [EMPTY] * len(box)
    return box


def _combine(verdicts: list[str]) -> str:
    if "wider" in verdicts:
        return "wider"
    return "tighter" if "tighter" in verdicts else "equal"


def record(case: str, verdict: str, detail: str = "") -> str:
    """Count the verdict; a wider case must be listed in :data:`WIDER`, a listed one must stay wider."""
    TALLY[verdict] += 1
    if verdict == "wider":
        assert case in WIDER, f"{case}: wider than the peer and not explained in judge.WIDER: {detail}"
    else:
        assert case not in WIDER, f"{case}: listed in judge.WIDER but now {verdict}: remove the entry"
    return verdict


def ours_of(iv: Any) -> tuple[float, float]:
    """``(lo, hi)`` floats of one of our intervals (an IntervalArray of shape () or (1,))."""
    lo, hi = np.ravel(iv.lo), np.ravel(iv.hi)
    return (INF, -INF) if lo[0] > hi[0] else (float(lo[0]), float(hi[0]))


def box_of(iv: Any) -> list[tuple[float, float]]:
    lo, hi = np.ravel(iv.lo), np.ravel(iv.hi)
    if (lo > hi).any():
        return [EMPTY] * lo.size
    return [(float(a), float(b)) for a, b in zip(lo, hi)]


def sampled_hull(
    box: Sequence[Sequence[float]], member: Callable[..., bool], k: int = 41, extra: Sequence[Any] = ()
) -> list[tuple[Any, Any]]:
    """Hull of the points of a ``k``-grid of the (bounded part of the) box, plus ``extra`` points, for
    which ``member`` holds at 200 bits: a subset of the true hull, so a necessary condition for
    soundness."""
    axes = []
    for lo, hi in box:
        lo, hi = max(lo, -1e3), min(hi, 1e3)
        axes.append([mpf(lo) + (mpf(hi) - mpf(lo)) * i / (k - 1) for i in range(k)] if hi > lo else [mpf(lo)])
    pts = [
        tuple(p) for p in np.array(np.meshgrid(*axes, indexing="ij"), dtype=object).reshape(len(box), -1).T
    ]
    pts += [tuple(mpf(c) for c in p) for p in extra]
    res: list[tuple[Any, Any]] = [EMPTY] * len(box)
    with mpmath.workprec(PREC):
        for p in pts:
            if all(lo <= c <= hi for c, (lo, hi) in zip(p, box)) and member(*p):
                res = [hull(r, (c, c)) for r, c in zip(res, p)]
    return res
