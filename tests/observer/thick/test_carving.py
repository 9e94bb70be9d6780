"""Contractors on thick sets and SRAC (thesis §5.5, Prop. 5.2–5.5, Algorithm 5.1, Example 5.5).

Soundness by sampling: true triples ``(p, A, B)`` with ``A ∈ [A]``, ``B ∈ [B]`` and ``f_p(A) = B`` (or
``⊂``, ``∩ ≠ ∅``) are drawn at random (disks of random centre and radius between the bounds); the true
``p`` must stay in the contracted ``[p]`` and the carved thick sets must still contain ``A`` and ``B``.
"""

from __future__ import annotations

import numpy as np
import pytest
from example_loader import load

from digslam.observer import Function, Interval, SepInverse, Transform
from digslam.observer.sets.registration import translation
from digslam.observer.thick.carving import (
    ctc_image_equal,
    ctc_image_param,
    ctc_param_equal,
    ctc_param_meets,
    ctc_param_subset,
    param_hull,
    srac,
)
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.sep import ThickSep

CA, CB = np.array([0.0, 0.0]), np.array([2.0, 1.0])  # centres of [A] and [B]: the true p is about CB - CA
P0 = [(-1.0, 4.0), (-2.0, 3.0)]
BOX_A, BOX_B = [(-1.2, 1.2), (-1.2, 1.2)], [(0.8, 3.2), (-0.2, 2.2)]


def disk(c: np.ndarray, r: float) -> SepInverse:
    c0, c1 = float(c[0]), float(c[1])
    return SepInverse(Function(lambda x: (x[0] - c0) ** 2 + (x[1] - c1) ** 2), Interval(-np.inf, r * r))


def thick_disk(c: np.ndarray, r_lo: float, r_hi: float) -> ThickSep:
    return ThickSep(disk(c, r_lo), disk(c, r_hi))


def minus(b: object, p: object) -> tuple:
    return b[0] - p[0], b[1] - p[1]  # type: ignore[index]


minus.q = 2  # type: ignore[attr-defined]
A = thick_disk(CA, 0.8, 1.2)
B = thick_disk(CB, 0.9, 1.1)


def true_triples(rng: np.random.Generator, k: int) -> list[tuple[np.ndarray, np.ndarray, float, np.ndarray]]:
    """``(p, centre of A, radius, centre of B)`` with disks A ∈ [A], B = A + p ∈ [B]."""
    out = []
    for _ in range(k):
        u, w = rng.uniform(-0.07, 0.07, (2, 2))
        m = max(np.hypot(*u), np.hypot(*w))
        rho = rng.uniform(0.9 + m, 1.1 - m)  # D(CA+u, ρ) ∈ [A] and D(CB+w, ρ) ∈ [B]
        out.append((CB + w - CA - u, CA + u, rho, CB + w))
    return out


def in_p(p: np.ndarray, box: tuple[np.ndarray, np.ndarray]) -> bool:
    return bool(((box[0] <= p) & (p <= box[1])).all())


def assert_contains_disk(
    ts: ThickSep, c: np.ndarray, rho: float, rng: np.random.Generator, frame: float = 2.0
) -> np.ndarray:
    """The thin disk D(c, ρ) is in the thick set: clear boxes inside it, dark boxes disjoint from it."""
    cen = rng.uniform(c - frame, c + frame, (250, 2))
    h = rng.uniform(0.02, 0.3, (250, 2))
    lo, hi = cen - h, cen + h
    st = ts.classify(lo, hi)
    u = rng.uniform(0, 1, (250, 40, 2))
    u[:, 0], u[:, 1] = 0.0, 1.0
    pts = lo[:, None] + u * (hi - lo)[:, None]
    d2 = ((pts - c) ** 2).sum(axis=-1)
    assert (d2 <= rho * rho + 1e-9)[st == CLEAR].all(), "a clear box leaves the true thin set"
    assert not (d2 <= rho * rho - 1e-9)[st == DARK].any(), "a dark box meets the true thin set"
    return st


def test_param_hull_basics() -> None:
    lo, hi = param_hull(disk(np.array([1.0, 1.0]), 0.5), [(-2, 2), (-2, 2)], 0.01)
    assert np.all(lo <= 0.5) and np.all(hi >= 1.5) and np.all(lo >= 0.49) and np.all(hi <= 1.51)
    lo, hi = param_hull(disk(np.array([5.0, 5.0]), 0.5), [(-2, 2), (-2, 2)], 0.05)
    assert np.all(lo > hi)  # all excluded: empty
    with pytest.raises(ValueError, match="eps"):
        param_hull(disk(np.array([1.0, 1.0]), 0.5), [(-2, 2), (-2, 2)], 0.0)
    with pytest.raises(ValueError, match="sep"):
        param_hull([], [(-2, 2), (-2, 2)], 0.1)


def test_registration_contractors_sound() -> None:
    """Prop. 5.4, Remark 5.7, Prop. 5.5: sampled true p are never removed; the box shrinks."""
    rng = np.random.default_rng(3)
    kw = {"eps": 0.2, "eps_p": 0.1, "max_splits": 32}
    p_sub = ctc_param_subset(P0, A, B, translation(2), BOX_A, **kw)
    p_eq = ctc_param_equal(P0, A, B, translation(2), minus, BOX_A, BOX_B, **kw)
    p_meet = ctc_param_meets(P0, A, B, translation(2), BOX_A, **kw)
    for p, *_ in true_triples(rng, 40):
        assert in_p(p, p_sub) and in_p(p, p_eq) and in_p(p, p_meet)
    # f_p(A) ∩ B ≠ ∅ for random disks A ∈ [A], B ∈ [B] and random p of P0 (Prop. 5.5)
    u, w = rng.uniform(-0.1, 0.1, (2, 400, 2))
    ra, rb = rng.uniform(0.9, 1.1, (2, 400))
    p = rng.uniform(np.array(P0)[:, 0], np.array(P0)[:, 1], (400, 2))
    nu, nw = np.hypot(*u.T), np.hypot(*w.T)
    valid = (ra - nu >= 0.8) & (ra + nu <= 1.2) & (rb - nw >= 0.9) & (rb + nw <= 1.1)  # A ∈ [A], B ∈ [B]
    meets = valid & (np.hypot(*(CA + u + p - CB - w).T) <= ra + rb)
    assert meets.sum() > 20
    assert all(in_p(q, p_meet) for q in p[meets])
    w0 = np.array([b - a for a, b in P0])
    for box in (p_sub, p_eq, p_meet):
        assert np.all(box[1] - box[0] < w0)
    # exact feasible sets: |p - (2, 1)| <= 0.3 (A⁻ + p ⊂ B⁺ and B⁻ - p ⊂ A⁺), |p - (2, 1)| <= 2.3 (meets)
    for box in (p_sub, p_eq):
        assert np.all(box[0] <= CB - 0.3) and np.all(box[1] >= CB + 0.3)
        assert np.all(box[1] - box[0] <= 0.6 + 0.3)
    p0_lo, p0_hi = np.array(P0)[:, 0], np.array(P0)[:, 1]
    assert np.all(p_meet[0] <= np.maximum(p0_lo, CB - 2.3)) and np.all(
        p_meet[1] >= np.minimum(p0_hi, CB + 2.3)
    )


def test_image_contractor_bijection() -> None:
    """Prop. 5.2 with f(x) = x + (2, 1): [A] and [B] both become [D(0.9), D(1.1)] (up to translation)."""
    rng = np.random.default_rng(4)
    t = Transform(Function(lambda x: (x[0] + 2, x[1] + 1)), Function(lambda y: (y[0] - 2, y[1] - 1)))
    a2, b2 = ctc_image_equal(A, B, t)
    st_a = assert_contains_disk(a2, CA, 0.95, rng)  # f(D(CA, ρ)) = D(CB, ρ) for every ρ ∈ [0.9, 1.1]
    assert_contains_disk(b2, CB, 1.05, rng)
    # clear ⊂ D(0.9) ∪ D(0.8) and dark ∩ D(1.1) = ∅: a box in the ring 1.12–1.18 is now dark
    assert a2.classify(np.array([[1.12, -0.02]]), np.array([[1.18, 0.02]])).tolist() == [DARK]
    assert A.classify(np.array([[1.12, -0.02]]), np.array([[1.18, 0.02]])).tolist() == [PENUMBRA]
    assert (st_a == CLEAR).any()


def test_carving_contains_true_sets() -> None:
    """Prop. 5.3 with p ∈ [p]: carved [A], [B] contain every sampled true A, B."""
    rng = np.random.default_rng(5)
    p_box = [(1.7, 2.3), (0.7, 1.3)]  # holds every sampled true p (|p - (2, 1)| <= 0.2)
    for equal in (True, False):
        a2, b2 = ctc_image_param(A, B, translation(2), minus, p_box, n=2, eps=0.1, equal=equal)
        for p, ca, rho, cb in true_triples(rng, 2):
            assert in_p(p, (np.array([1.7, 0.7]), np.array([2.3, 1.3])))
            assert_contains_disk(a2, ca, rho, rng)
            assert_contains_disk(b2, cb, rho, rng)
    # with p ∈ (2, 1) ± 0.05 the carving moves both bounds of [A]: A⁺ ⊂ D(1.1 + 0.05·√2), A⁻ ⊃ D(0.9 - 0.05·√2)
    a2, _ = ctc_image_param(A, B, translation(2), minus, [(1.95, 2.05), (0.95, 1.05)], n=2, eps=0.05)
    boxes = (np.array([[1.18, -0.01], [0.81, -0.01]]), np.array([[1.19, 0.01], [0.82, 0.01]]))
    assert A.classify(*boxes).tolist() == [PENUMBRA, PENUMBRA]
    assert a2.classify(*boxes).tolist() == [DARK, CLEAR]


def test_srac_sound() -> None:
    rng = np.random.default_rng(6)
    r = srac(translation(2), minus, P0, A, B, BOX_A, BOX_B, eps=0.1, eps_p=0.05, max_splits=64)
    assert not r.empty
    for triple in true_triples(rng, 30):
        assert in_p(triple[0], r.p)
    for _, ca, rho, cb in true_triples(rng, 2):
        assert_contains_disk(r.a, ca, rho, rng)
        assert_contains_disk(r.b, cb, rho, rng)
    far = thick_disk(np.array([9.0, 9.0]), 0.9, 1.1)  # no translation in P0 maps [A] onto it
    r2 = srac(translation(2), minus, P0, A, far, BOX_A, [(7.8, 10.2), (7.8, 10.2)], eps=0.2, eps_p=0.1)
    assert r2.empty and r2.a is A


def _check_ex5_5(r: dict, max_width: tuple[float, float]) -> None:
    assert r["contains_p_star"] and not r["empty"]
    assert r["width"][0] <= max_width[0] and r["width"][1] <= max_width[1]


def test_ex5_5_coarse() -> None:
    """Example 5.5 at a coarse paving: sound, [p] much narrower than [p]₀."""
    ex = load("ex5_5_srac")
    r = ex.run(eps=0.2, out=None, max_splits=16)
    _check_ex5_5(r, (1.0, 0.6))  # measured 0.856 x 0.485


@pytest.mark.expensive
def test_ex5_5_published(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Example 5.5: [p] ∋ p* and no wider than the published [2.65113, 2.90901] × [-1.14117, -0.95238]."""
    ex = load("ex5_5_srac")
    r = ex.run(eps=0.01, out=tmp_path)
    _check_ex5_5(r, tuple(r["published_width"]))
    assert (tmp_path / "ex5_5_srac.png").exists()
