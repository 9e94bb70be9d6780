"""The centred backward contraction (:mod:`digslam.observer.expr.centred_ctc`): it never loses a point
of ``{x | f(x) ∈ [y]}`` (hypothesis, points checked in exact rational arithmetic) and it contracts where
HC4 cannot (a variable occurring several times)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer import CtcFwdBwd, Function, Interval, SepInverse
from digslam.observer.expr.centred_ctc import centred_contract

F = Function(lambda x: x[0] * x[0] - 2 * x[0] * x[1] + x[1] * x[1] + x[0], n=2)


def f_exact(a: float, b: float) -> Fraction:
    a_, b_ = Fraction(a), Fraction(b)
    return a_ * a_ - 2 * a_ * b_ + b_ * b_ + a_


@settings(max_examples=60, deadline=None)
@given(st.floats(-2, 2), st.floats(-2, 2), st.floats(0.01, 1), st.floats(-1, 3), st.floats(0, 1))
def test_no_point_of_the_set_is_lost(cx: float, cy: float, w: float, y0: float, yw: float) -> None:
    lo, hi = np.array([[cx - w, cy - w]]), np.array([[cx + w, cy + w]])
    clo, chi = centred_contract(F, lo, hi, np.array([[y0]]), np.array([[y0 + yw]]))
    rng = np.random.default_rng(0)
    for a, b in rng.uniform(lo[0], hi[0], (300, 2)):
        if Fraction(y0) <= f_exact(a, b) <= Fraction(y0 + yw):
            assert clo[0, 0] <= a <= chi[0, 0] and clo[0, 1] <= b <= chi[0, 1]


def test_contracts_where_hc4_cannot() -> None:
    """``(x0 - x1)² + x0 = 1.0`` near ``(1, 1)``: HC4 keeps most of the box, the centred pass does not."""
    lo, hi = np.array([[0.9, 0.95]]), np.array([[1.1, 1.05]])
    hlo, hhi = CtcFwdBwd(F, (1.0, 1.0)).contract(lo, hi)
    clo, chi = CtcFwdBwd(F, (1.0, 1.0), centred=True).contract(lo, hi)
    assert (chi - clo)[0, 0] < 0.5 * (hhi - hlo)[0, 0]
    assert clo[0, 0] <= 1.0 <= chi[0, 0]  # (1, 1) is a solution


def test_separator_parts_stay_a_cover() -> None:
    """With ``centred=True`` both parts of ``SepInverse`` still cover every point of the box."""
    s = SepInverse(F, Interval(0.5, 1.0), centred=True)
    rng = np.random.default_rng(1)
    c = rng.uniform(-1.5, 1.5, (50, 2))
    lo, hi = c - 0.05, c + 0.05
    (ilo, ihi), (olo, ohi) = s.separate(lo, hi)
    for r in range(50):
        for a, b in rng.uniform(lo[r], hi[r], (100, 2)):
            v = f_exact(a, b)
            if Fraction(0.5) <= v <= 1:
                assert (olo[r] <= (a, b)).all() and ((a, b) <= ohi[r]).all()
            else:
                assert (ilo[r] <= (a, b)).all() and ((a, b) <= ihi[r]).all()
