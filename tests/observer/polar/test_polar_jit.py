"""The compiled polar contractor and pie separator (observer/core/polar_jit.py) against the numpy oracle.

The numpy construction of ``tests/polar_oracle.py`` (:func:`contract_polar`, :func:`sep_pie_numpy`) is the
reference:
the compiled boxes must keep every sampled solution, never be empty where it is not, and agree with
it up to outward rounding (the compiled kernels step round-to-nearest results out by an ulp where the
numpy kernels round exactly: after cancellation in ``ρ² - a²`` this is ~1e-14 absolute).
"""

from __future__ import annotations

import numpy as np
import pytest
from polar_boxes import random_boxes
from polar_oracle import CtcPolarNumpy, contract_polar, sep_landmark_numpy, sep_pie_numpy

from digslam.observer.core.polar_jit import ctc_polar_batch
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.polar.sep import SepLandmark, SepPiInv
from digslam.observer.sets.separators import check_separation

TOL = 1e-12


def _empty(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return (lo > hi).any(axis=1)


def _agree(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> None:
    """``b`` (compiled) equals ``a`` (numpy) up to rounding: same empty rows, bounds within TOL."""
    ea, eb = _empty(*a), _empty(*b)
    assert (ea == eb).all(), f"rows emptied differently: {np.flatnonzero(ea != eb)[:5]}"
    ok = ~ea
    for u, v in ((a[0][ok], b[0][ok]), (a[1][ok], b[1][ok])):
        fin = np.isfinite(u)
        assert (u[~fin] == v[~fin]).all(), "infinite bounds differ"
        u, v = u[fin], v[fin]
        assert (np.abs(u - v) <= TOL * (1 + np.abs(u))).all(), f"differs from numpy by {np.abs(u - v).max()}"
    assert (b[0][ok] >= a[0][ok] - TOL * (1 + np.abs(a[0][ok]))).all(), "compiled box larger than numpy"


@pytest.mark.parametrize("need_theta", [True, False])
def test_compiled_contractor_equals_numpy(need_theta: bool) -> None:
    lo, hi = random_boxes(np.random.default_rng(11), 3000)
    _agree(contract_polar(lo, hi, need_theta), ctc_polar_batch(lo, hi, need_theta))


def test_compiled_contractor_keeps_sampled_solutions() -> None:
    rng = np.random.default_rng(12)
    n = 5000
    r, t = rng.uniform(-6, 6, n), rng.uniform(-40, 40, n)
    p = np.c_[r * np.cos(t), r * np.sin(t), r, t]
    lo = p - rng.uniform(1e-9, 3, (n, 4)) * (rng.random((n, 4)) < 0.8) - 1e-9
    hi = p + rng.uniform(1e-9, 3, (n, 4)) * (rng.random((n, 4)) < 0.8) + 1e-9
    for nt in (True, False):
        rlo, rhi = CtcPolar(nt).contract(lo, hi)
        assert ((rlo <= p) & (p <= rhi)).all()


def test_compiled_contractor_special_boxes() -> None:
    inf = np.inf
    lo = np.array([[-inf, -inf, 1.0, -inf], [0.0, 0.0, 0.0, 0.5], [3.0, 3.0, 0.0, -1.0], [1.0, 1.0, 0.0, 0.0],
                   [-1.0, -1.0, -0.5, 0.1], [inf, 0.0, 0.0, 0.0]])  # fmt: skip
    hi = np.array([[inf, inf, 2.0, inf], [0.0, 0.0, 0.0, 0.5], [4.0, 4.0, 1.0, 1.0], [2.0, 2.0, 10.0, 0.0],
                   [1.0, 1.0, 5.0, 0.2], [-inf, 1.0, 1.0, 1.0]])  # fmt: skip
    clo, chi = CtcPolar().contract(lo, hi)
    assert clo[0].tolist() == [-2, -2, 1, -inf] and chi[0].tolist() == [2, 2, 2, inf]  # clipped only
    assert clo[1].tolist() == [0, 0, 0, 0.5] == [*chi[1, :3], 0.5]  # the origin, any θ
    assert _empty(clo, chi)[[2, 3, 5]].all()  # ring misses the box; ray θ = 0 misses y >= 1; empty input
    assert (
        clo[4, 2:].tolist() == [-0.5, 0.1] and chi[4, 0] == 1.0 and chi[4, 3] == 0.2
    )  # origin inside, ρ < 0
    _agree(contract_polar(lo, hi), (clo, chi))
    with pytest.raises(ValueError, match="shape"):
        CtcPolar().contract(np.zeros((2, 3)), np.ones((2, 3)))


def test_numpy_oracle_class_is_the_same_contractor() -> None:
    lo, hi = random_boxes(np.random.default_rng(13), 500)
    _agree(CtcPolarNumpy().contract(lo, hi), CtcPolar().contract(lo, hi))


@pytest.mark.parametrize(
    "rho, theta",
    [((2.1, 4.0), (np.pi / 12, 3 * np.pi / 4)), ((2.1, 4.0), (-2.0, 2.5)), ((0.0, np.inf), (1.0, 6.0))],
)
def test_compiled_pie_separator_equals_numpy(rho: tuple[float, float], theta: tuple[float, float]) -> None:
    rng = np.random.default_rng(14)
    c, w = rng.uniform(-6, 6, (4000, 2)), rng.uniform(0, 2, (4000, 2))
    lo, hi = c - w, c + w
    lo[:3], hi[:3] = (
        [[-np.inf, -np.inf], [1.0, -np.inf], [-np.inf, -1.0]],
        [[np.inf, np.inf], [np.inf, 2.0], [0.5, 3.0]],
    )
    s = SepPiInv(rho, theta)
    (ilo, ihi), (olo, ohi) = s.separate(lo, hi)
    (nilo, nihi), (nolo, nohi) = sep_pie_numpy(s, lo, hi)
    _agree((nilo, nihi), (ilo, ihi))
    _agree((nolo, nohi), (olo, ohi))
    assert not check_separation((ilo, ihi), (olo, ohi), lo, hi).any()
    lo, hi, ilo, ihi, olo, ohi = (v[3:] for v in (lo, hi, ilo, ihi, olo, ohi))  # sample the bounded ones
    pts = rng.uniform(lo, hi)
    r, t = np.hypot(pts[:, 0], pts[:, 1]), np.arctan2(pts[:, 1], pts[:, 0])
    t = np.where(t < theta[0], t + 2 * np.pi, t)
    inside = (r >= rho[0]) & (r <= rho[1]) & (t >= theta[0]) & (t <= theta[1])
    assert ((olo <= pts) & (pts <= ohi)).all(1)[inside].all()
    assert ((ilo <= pts) & (pts <= ihi)).all(1)[~inside].all()


def test_compiled_landmark_separator_equals_numpy() -> None:
    rng = np.random.default_rng(15)
    c, w = rng.uniform(-6, 4, (3000, 2)), rng.uniform(0, 1, (3000, 2))
    lo, hi = c - w, c + w
    s = SepLandmark((0.5, -1.0), (4.0, 6.0), (-np.pi / 12, np.pi / 4))
    a, b = s.separate(lo, hi), sep_landmark_numpy(s, lo, hi)
    _agree(b[0], a[0])
    _agree(b[1], a[1])
    st = s.separate_stacked(lo, hi)
    assert st.shape == (4, 3000, 2) and (st[0] == a[0][0]).all() and (st[3] == a[1][1]).all()
    with pytest.raises(ValueError, match="lo, hi"):
        s.separate(np.zeros((2, 3)), np.ones((2, 3)))
