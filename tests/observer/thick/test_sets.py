"""Thick separators and their algebra (thesis §5.2–5.3): soundness by sampling."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from digslam.observer import Box, SepBox
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.sep import (
    ThickSep,
    thick_classify_grid,
    thick_relaxed_intersection,
)

Pred = Callable[[np.ndarray], np.ndarray]


def in_box(lo: list[float], hi: list[float]) -> Pred:
    lo_, hi_ = np.asarray(lo), np.asarray(hi)
    return lambda p: ((p >= lo_) & (p <= hi_)).all(axis=-1)


def thick_box(lo_m: list[float], hi_m: list[float], lo_p: list[float], hi_p: list[float]) -> tuple:
    ts = ThickSep(SepBox(Box(list(zip(lo_m, hi_m)))), SepBox(Box(list(zip(lo_p, hi_p)))))
    return ts, in_box(lo_m, hi_m), in_box(lo_p, hi_p)


A, A_MINUS, A_PLUS = thick_box([-1, -1], [1, 1], [-2, -2], [2, 2])
B, B_MINUS, B_PLUS = thick_box([0, -0.5], [3, 0.5], [-0.5, -1.5], [3.5, 1.5])


def random_batch(rng: np.random.Generator, n: int = 400, scale: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    c = rng.uniform(-scale, scale, (n, 2))
    w = rng.uniform(0.0, 1.5, (n, 2))
    return c - w, c + w


def samples(lo: np.ndarray, hi: np.ndarray, rng: np.random.Generator, k: int = 64) -> np.ndarray:
    """``(N, k, 2)`` points of each box, corners included."""
    u = rng.uniform(0, 1, (lo.shape[0], k, 2))
    u[:, :4] = np.array([[0, 0], [0, 1], [1, 0], [1, 1]])
    return np.clip(lo[:, None] + u * (hi - lo)[:, None], lo[:, None], hi[:, None])


def in_batch(p: np.ndarray, b: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    return ((p >= b[0][:, None]) & (p <= b[1][:, None])).all(axis=-1)


def check_sound(ts: ThickSep, minus: Pred, plus: Pred, seed: int = 0) -> np.ndarray:
    """Eq. 5.18 and the classification, checked on sampled points; returns the statuses."""
    rng = np.random.default_rng(seed)
    lo, hi = random_batch(rng)
    p = samples(lo, hi, rng)
    xm, xp = minus(p), plus(p)
    assert not (xm & ~xp).any(), "test set-up: X⁻ ⊄ X⁺"
    xin, xq, xout = ts.separate(lo, hi)
    # each part keeps its zone; together they cover the box (invariant of Eq. 5.18)
    assert in_batch(p, xin)[xm].all()
    assert in_batch(p, xq)[xp & ~xm].all()
    assert in_batch(p, xout)[~xp].all()
    for part in (xin, xq, xout):
        ok = np.isinf(part[0]).all(axis=1) | ((part[0] >= lo) & (part[1] <= hi)).all(axis=1)
        assert ok.all(), "a part is not inside its box"
    st = ts.classify(lo, hi)
    # random thin sets X⁻ ⊂ X ⊂ X⁺: a thin set is X⁻ plus a random subset of the penumbra
    for _ in range(5):
        x = xm | (xp & (rng.uniform(size=xm.shape) < 0.5))
        assert x[st == CLEAR].all(), "a clear box has a point outside some X ∈ [X]"
    assert xm[st == CLEAR].all()
    assert not xp[st == DARK].any(), "a dark box meets X⁺"
    pen = st == PENUMBRA
    assert (xp & ~xm)[pen].all(), "a penumbra box leaves X⁺ \\ X⁻"
    return st


def test_base_sound_and_all_statuses() -> None:
    st = check_sound(A, A_MINUS, A_PLUS)
    assert {int(v) for v in np.unique(st)} == {-1, 0, 1, 2}


@pytest.mark.parametrize(
    "name, ts, minus, plus",
    [
        ("inter", A & B, lambda p: A_MINUS(p) & B_MINUS(p), lambda p: A_PLUS(p) & B_PLUS(p)),
        ("union", A | B, lambda p: A_MINUS(p) | B_MINUS(p), lambda p: A_PLUS(p) | B_PLUS(p)),
        ("complement", ~A, lambda p: ~A_PLUS(p), lambda p: ~A_MINUS(p)),
        ("restriction", A - B, lambda p: A_MINUS(p) & ~B_PLUS(p), lambda p: A_PLUS(p) & ~B_MINUS(p)),
        ("join", A.join(B), lambda p: A_MINUS(p) & B_MINUS(p), lambda p: A_PLUS(p) | B_PLUS(p)),
    ],
)
def test_algebra_sound(name: str, ts: ThickSep, minus: Pred, plus: Pred) -> None:
    check_sound(ts, minus, plus, seed=hash(name) % 1000)


def test_meet_lattice_intersection() -> None:
    # [X] ⊓ [Y] = [X⁻ ∪ Y⁻, X⁺ ∩ Y⁺] (Eq. 5.16): needs X⁻ ∪ Y⁻ ⊂ X⁺ ∩ Y⁺
    c, c_m, c_p = thick_box([-0.5, -0.5], [0.5, 0.5], [-3, -3], [3, 3])
    check_sound(A.meet(c), lambda p: A_MINUS(p) | c_m(p), lambda p: A_PLUS(p) & c_p(p))


def test_extension_intersection_numbers() -> None:
    lo, hi = np.array([[0.2, -0.4], [1.2, 0.6], [5.0, 5.0]]), np.array([[0.8, 0.4], [1.8, 1.2], [6.0, 6.0]])
    assert (A & B).classify(lo, hi).tolist() == [1, 2, -1]
    assert (~(A & B)).classify(lo, hi).tolist() == [-1, 2, 1]


def test_relaxed_intersection() -> None:
    c, c_m, c_p = thick_box([-1, -1], [0, 0], [-1.5, -1.5], [0.5, 0.5])
    r = thick_relaxed_intersection([A, B, c], 1)

    def at_least(preds: list[Pred]) -> Pred:
        return lambda p: sum(f(p).astype(int) for f in preds) >= 2

    check_sound(r, at_least([A_MINUS, B_MINUS, c_m]), at_least([A_PLUS, B_PLUS, c_p]), seed=3)
    with pytest.raises(ValueError, match="q"):
        thick_relaxed_intersection([A, B], 2)


def test_grid_classification() -> None:
    g = thick_classify_grid(([-4.2, -4.2], [4.2, 4.2]), A, (20, 20))
    assert g.shape == (20, 20) and g.dtype == np.int8
    assert g[10, 10] == CLEAR and g[0, 0] == DARK and g[6, 10] == PENUMBRA  # cell y ∈ [1.26, 1.68]
    assert set(np.unique(g).tolist()) <= {-1, 0, 1, 2}
    with pytest.raises(ValueError, match="2-d box"):
        thick_classify_grid(([0.0], [1.0]), A, (4, 4))


def test_bad_input() -> None:
    bad = ThickSep(SepBox(Box([(0, 2), (0, 2)])), SepBox(Box([(-1, 1), (-1, 1)])))
    with pytest.raises(ValueError, match="lower bound not inside upper bound"):
        bad.classify(np.array([[1.5, 1.5]]), np.array([[1.8, 1.8]]))
    with pytest.raises(TypeError, match="expected two Sep"):
        ThickSep(SepBox(Box([(0, 1)])), None)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="mismatched"):
        ThickSep(SepBox(Box([(0, 1)])), SepBox(Box([(0, 1), (0, 1)])))


def test_ctc_subset_and_equal() -> None:
    from digslam.observer.thick.set import ctc_equal, ctc_subset

    c, c_m, c_p = thick_box([-0.5, -0.5], [0.5, 0.5], [-3, -3], [1.5, 1.5])
    a2, c2 = ctc_subset(A, c)  # Eq. 5.46
    check_sound(a2, A_MINUS, lambda p: A_PLUS(p) & c_p(p), seed=5)
    check_sound(c2, lambda p: c_m(p) | A_MINUS(p), c_p, seed=6)
    a3, c3 = ctc_equal(A, c)
    for t in (a3, c3):
        check_sound(t, lambda p: A_MINUS(p) | c_m(p), lambda p: A_PLUS(p) & c_p(p), seed=7)
    with pytest.raises(TypeError, match="ThickSep"):
        ctc_subset(A, None)  # type: ignore[arg-type]
