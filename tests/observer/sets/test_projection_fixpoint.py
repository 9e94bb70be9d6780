"""``SepProj(..., fixpoint=True)`` (issue 24, item 5): the projection iterated on its own results until it
stalls (§4.2.1), on codac's SepProj test (an ellipsoidal shell projected along ``x2 ∈ [0.1, 0.2]``).
The true bound is computed in exact arithmetic (mpmath, the larger root of a quadratic in ``x1``)."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepInverse
from digslam.observer.expr.ops import sqr
from digslam.observer.sets.projection import SepProj

mpmath.mp.dps = 40


def _shell(centred: bool = False) -> SepInverse:
    f = Function(lambda x: 2 * sqr(x[0]) + x[0] * x[1] + x[0] * x[2] + sqr(x[1]) + sqr(x[2]), n=3)
    return SepInverse(f, Interval(0.7, 1), centred=centred)


def _true_x1_max(x0: tuple[float, float], x2: tuple[float, float], k: int = 201) -> mpmath.mpf:
    """``max x1`` with ``f <= 1`` over a grid of ``(x0, x2)`` (a lower bound of the true maximum)."""
    best = mpmath.mpf(-10)
    for a in np.linspace(*x0, k):
        for c in np.linspace(*x2, 21):
            a_, c_ = mpmath.mpf(a), mpmath.mpf(c)
            q = 2 * a_**2 + a_ * c_ + c_**2 - 1  # x1² + a x1 + q <= 0
            disc = a_**2 - 4 * q
            if disc >= 0:
                best = max(best, (-a_ + mpmath.sqrt(disc)) / 2)
    return best


def test_fixpoint_tightens_the_outer_bound() -> None:
    box = Box([(-0.4, -0.2), (0.95, 1.5)])
    once = SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-3)
    fix = SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=True)
    _, out1 = once(box)
    _, outf = fix(box)
    truth = _true_x1_max((-0.4, -0.2), (0.1, 0.2))
    assert 1.07 < truth < 1.09
    assert truth <= mpmath.mpf(float(outf.hi[1])) <= float(out1.hi[1])  # sound and no wider
    assert float(outf.hi[1]) < 1.21 < float(out1.hi[1])  # 1.249 after one pass, 1.200 at the fixpoint
    assert fix.rounds > once.rounds


def test_centred_inner_separator_beats_the_peer() -> None:
    """With the centred backward contraction in the inner separator (codac's SepInverse default) the bound
    drops from 1.200 to 1.117: below codac's 1.15, above the truth 1.08."""
    box = Box([(-0.4, -0.2), (0.95, 1.5)])
    sp = SepProj(_shell(centred=True), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=True)
    xin, xout = sp(box)
    truth = _true_x1_max((-0.4, -0.2), (0.1, 0.2))
    assert truth <= mpmath.mpf(float(xout.hi[1])) < 1.12
    assert float(xin.hi[1]) == 1.5 and float(xout.lo[1]) == 0.95


@pytest.mark.parametrize("fixpoint", [False, True])
def test_codac_cases(fixpoint: bool) -> None:
    sp = SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=fixpoint)
    _, xout = sp(Box([(0.2, 0.4), (0.0, 1.0)]))
    assert abs(float(xout.hi[1]) - 0.94) < 1e-2 and float(xout.lo[1]) == 0.0
    xin, _ = sp(Box([(0.65, 0.65), (-0.5, -0.4)]))
    assert bool(xin.is_empty().all())


def test_fixpoint_is_a_separator() -> None:
    """``x_in ∪ x_out = x`` and no sampled point of the projection leaves ``x_out``, none outside it
    leaves ``x_in``."""
    rng = np.random.default_rng(0)
    sp = SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-2, fixpoint=True)
    c = rng.uniform(-1.2, 1.2, (40, 2))
    lo, hi = c - 0.1, c + 0.1
    (ilo, ihi), (olo, ohi) = sp.separate(lo, hi)
    f = lambda a, b, z: 2 * a * a + a * b + a * z + b * b + z * z  # noqa: E731
    zs = np.linspace(0.1, 0.2, 11)
    for r in range(lo.shape[0]):
        pts = rng.uniform(lo[r], hi[r], (200, 2))
        vals = np.stack([f(pts[:, 0], pts[:, 1], z) for z in zs])
        inside = ((vals >= 0.7) & (vals <= 1.0)).any(axis=0)
        clear_out = ((vals < 0.69) | (vals > 1.01)).all(axis=0)  # margin: zs is a sample of [0.1, 0.2]
        in_out = ((pts >= olo[r]) & (pts <= ohi[r])).all(axis=1)
        in_in = ((pts >= ilo[r]) & (pts <= ihi[r])).all(axis=1)
        assert in_out[inside].all()
        assert in_in[clear_out].all()
        assert (in_out | in_in).all()


def test_fixpoint_arguments() -> None:
    with pytest.raises(ValueError, match="fixpoint_ratio"):
        SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=True, fixpoint_ratio=1.5)
    with pytest.raises(ValueError, match="max_rounds"):
        SepProj(_shell(), [0, 1], Box([(0.1, 0.2)]), eps=1e-3, max_rounds=0)
