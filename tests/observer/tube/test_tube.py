"""Tubes and the differential contractor ``C_d/dt`` (thesis §2.5.4, Example 2.9, Eq. 6.23 / B.20).

Soundness is checked against exact trajectories: piecewise-polynomial inputs ``u`` whose exact range
over each slice gives the interval input (so the truth can sit exactly on the bounds), the exact
trajectory computed with :class:`~fractions.Fraction` at the gates and at random times inside the
slices, and compared exactly with the float bounds. The vectorised contractor is also compared with a
straightforward sequential implementation.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.core import arith, trig
from digslam.observer.core import rounding as rnd
from digslam.observer.tube.ctc import cumsum_enclosure
from digslam.observer.tube.tube import (
    Tube,
    body_velocity,
    ctc_deriv,
    dead_reckoning,
    heading_from_compass,
    heading_from_gyro,
    unicycle_velocity,
)

INF = math.inf


# ---------------------------------------------------------------- exact helpers
def f_down(q: Fraction) -> float:
    f = float(q)
    return float(np.nextafter(f, -INF)) if Fraction(f) > q else f


def f_up(q: Fraction) -> float:
    f = float(q)
    return float(np.nextafter(f, INF)) if Fraction(f) < q else f


def inside(lo: float, hi: float, q: Fraction) -> bool:
    return (lo == -INF or Fraction(lo) <= q) and (hi == INF or q <= Fraction(hi))


class Truth:
    """Exact trajectory with ``u(τ) = a + b s + c s²`` on slice ``k`` (``s = τ - t_k``), per coordinate."""

    def __init__(self, rng: np.random.Generator, t: np.ndarray, n: int, kinds: tuple[int, ...] = (0, 1, 2)):
        T = t.size - 1
        self.t, self.n = t, n
        kind = rng.choice(kinds, size=(T, n))
        self.a = rng.uniform(-2, 2, (T, n))
        self.b = np.where(kind >= 1, rng.uniform(-3, 3, (T, n)), 0.0)
        self.c = np.where(kind >= 2, rng.uniform(-4, 4, (T, n)), 0.0)
        self.ft = [Fraction(float(v)) for v in t]
        x0 = rng.uniform(-5, 5, n)
        self.X = [[Fraction(float(v)) for v in x0]]
        self.u_lo, self.u_hi = np.empty((T, n)), np.empty((T, n))
        for k in range(T):
            dt = self.ft[k + 1] - self.ft[k]
            row = []
            for i in range(n):
                a, b, c = (Fraction(float(v[k, i])) for v in (self.a, self.b, self.c))
                cands = [a, a + b * dt + c * dt * dt]
                if c != 0 and 0 < -b / (2 * c) < dt:
                    s = -b / (2 * c)
                    cands.append(a + b * s + c * s * s)
                self.u_lo[k, i], self.u_hi[k, i] = f_down(min(cands)), f_up(max(cands))
                row.append(self.X[k][i] + a * dt + b * dt**2 / 2 + c * dt**3 / 3)
            self.X.append(row)

    def at(self, k: int, tau: float) -> list[Fraction]:
        s = Fraction(tau) - self.ft[k]
        return [
            self.X[k][i] + Fraction(float(self.a[k, i])) * s + Fraction(float(self.b[k, i])) * s**2 / 2
            + Fraction(float(self.c[k, i])) * s**3 / 3
            for i in range(self.n)
        ]  # fmt: skip


def random_grid(rng: np.random.Generator, T: int) -> np.ndarray:
    return rng.uniform(-3, 3) + np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.4, T))])


def assert_sound(x: Tube, truth: Truth, rng: np.random.Generator, per_slice: int = 4) -> None:
    assert not x.is_empty()
    for k in range(x.T + 1):
        for i in range(x.n):
            assert inside(x.gate_lo[k, i], x.gate_hi[k, i], truth.X[k][i]), (k, i)
    for k in range(x.T):
        taus = rng.uniform(x.t[k], x.t[k + 1], per_slice).tolist() + [x.t[k], x.t[k + 1]]
        for tau in taus:
            for i, q in enumerate(truth.at(k, tau)):
                assert inside(x.slice_lo[k, i], x.slice_hi[k, i], q), (k, tau, i)


def fixes(rng: np.random.Generator, truth: Truth, x: Tube, count: int, tight: bool) -> Tube:
    """Gate constraints holding the exact state: intervals around it (points when ``tight``)."""
    x = x.copy()
    for k in rng.choice(x.T + 1, size=count, replace=False):
        for i in range(x.n):
            q = truth.X[k][i]
            w = (0.0, 0.0) if tight else rng.uniform(0, 0.3, 2)
            x.gate_lo[k, i] = f_down(q - Fraction(float(w[0])))
            x.gate_hi[k, i] = f_up(q + Fraction(float(w[1])))
    return x


# ---------------------------------------------------------------- sequential reference
def seq_ctc(x: Tube, u_lo: np.ndarray, u_hi: np.ndarray, forward: bool = True, backward: bool = True) -> Tube:
    """The contractor written as the plain loops of its definition (directed rounding at each step)."""
    t = x.t
    dt = (rnd.sub_down(t[1:], t[:-1])[:, None], rnd.sub_up(t[1:], t[:-1])[:, None])
    d_lo, d_hi = arith.mul(dt, (u_lo, u_hi))
    glo, ghi, slo, shi = x.gate_lo.copy(), x.gate_hi.copy(), x.slice_lo.copy(), x.slice_hi.copy()
    for k in range(x.T):
        glo[k] = np.maximum(glo[k], slo[k])
        ghi[k] = np.minimum(ghi[k], shi[k])
        glo[k + 1] = np.maximum(glo[k + 1], slo[k])
        ghi[k + 1] = np.minimum(ghi[k + 1], shi[k])
    if forward:
        for k in range(x.T):
            glo[k + 1] = np.maximum(glo[k + 1], rnd.add_down(glo[k], d_lo[k]))
            ghi[k + 1] = np.minimum(ghi[k + 1], rnd.add_up(ghi[k], d_hi[k]))
    if backward:
        for k in reversed(range(x.T)):
            glo[k] = np.maximum(glo[k], rnd.sub_down(glo[k + 1], d_hi[k]))
            ghi[k] = np.minimum(ghi[k], rnd.sub_up(ghi[k + 1], d_lo[k]))
    for k in range(x.T):
        slo[k] = np.maximum(slo[k], rnd.add_down(glo[k], np.minimum(d_lo[k], 0.0)))
        slo[k] = np.maximum(slo[k], rnd.sub_down(glo[k + 1], np.maximum(d_hi[k], 0.0)))
        shi[k] = np.minimum(shi[k], rnd.add_up(ghi[k], np.maximum(d_hi[k], 0.0)))
        shi[k] = np.minimum(shi[k], rnd.sub_up(ghi[k + 1], np.minimum(d_lo[k], 0.0)))
    for k in range(x.T):
        glo[k], ghi[k] = np.maximum(glo[k], slo[k]), np.minimum(ghi[k], shi[k])
        glo[k + 1], ghi[k + 1] = np.maximum(glo[k + 1], slo[k]), np.minimum(ghi[k + 1], shi[k])
    return Tube(t, glo, ghi, slo, shi)


def assert_close(a: np.ndarray, b: np.ndarray, T: int) -> None:
    assert np.array_equal(np.isinf(a), np.isinf(b)) and np.array_equal(a[np.isinf(a)], b[np.isinf(b)])
    fin = np.isfinite(a)
    scale = max(1.0, float(np.abs(a[fin]).max(initial=0.0)))
    assert np.abs(a[fin] - b[fin]).max(initial=0.0) <= (T + 4) * 2.0**-52 * scale


# ---------------------------------------------------------------- tests
@pytest.mark.parametrize("seed", range(8))
def test_soundness_random_trajectories(seed: int) -> None:
    rng = np.random.default_rng(seed)
    T, n = int(rng.integers(5, 40)), 2
    t = random_grid(rng, T)
    truth = Truth(rng, t, n)
    x = fixes(rng, truth, Tube.entire(t, n), count=int(rng.integers(1, 5)), tight=bool(seed % 2))
    for fw, bw in ((True, True), (True, False), (False, True)):
        y = ctc_deriv(x, truth.u_lo, truth.u_hi, forward=fw, backward=bw)
        assert_sound(y, truth, rng)
        assert_sound(ctc_deriv(y, truth.u_lo, truth.u_hi), truth, rng, per_slice=1)


def test_soundness_on_the_bounds_long_horizon() -> None:
    """Constant inputs (``[u_k]`` a point) from a point ``x(t_0)``: the truth is on both bounds, so every
    rounding matters. 12,000 irregular steps, then the final gate pinned and propagated back."""
    rng = np.random.default_rng(7)
    T = 12_000
    t = random_grid(rng, T)
    truth = Truth(rng, t, 2, kinds=(0,))
    assert np.array_equal(truth.u_lo, truth.u_hi)
    x0 = [float(v) for v in truth.X[0]]
    x = dead_reckoning(t, x0, x0, truth.u_lo, truth.u_hi)
    pinned = x.copy()
    pinned.gate_lo[-1] = [f_down(q) for q in truth.X[-1]]
    pinned.gate_hi[-1] = [f_up(q) for q in truth.X[-1]]
    y = ctc_deriv(pinned, truth.u_lo, truth.u_hi)
    for tube in (x, y):
        for k in range(0, T + 1, 7):
            for i in range(2):
                assert inside(tube.gate_lo[k, i], tube.gate_hi[k, i], truth.X[k][i])
    assert x.widths()[-1] < 1e-9  # rounding-level width after 12,000 steps


def test_given_slices_and_unbounded_inputs_sound() -> None:
    rng = np.random.default_rng(3)
    T = 30
    t = random_grid(rng, T)
    truth = Truth(rng, t, 2)
    u_lo, u_hi = truth.u_lo.copy(), truth.u_hi.copy()
    u_lo[5:8, 0], u_hi[12, 1], u_lo[20, :] = -INF, INF, -INF  # no information on some slices
    mag = np.maximum(np.abs(truth.u_lo), np.abs(truth.u_hi)) * np.diff(t)[:, None] + 0.01
    gates = np.array([[float(q) for q in row] for row in truth.X])
    s_lo = np.minimum(gates[:-1], gates[1:]) - mag  # rigorous slice envelopes (|x(τ) - x_k| <= max|u| dt)
    s_hi = np.maximum(gates[:-1], gates[1:]) + mag
    x = fixes(rng, truth, Tube(t, np.full((T + 1, 2), -INF), np.full((T + 1, 2), INF), s_lo, s_hi), 4, False)
    y = ctc_deriv(x, u_lo, u_hi)
    assert_sound(y, truth, rng)
    ref = seq_ctc(x, u_lo, u_hi)
    for a, b in ((y.gate_lo, ref.gate_lo), (y.gate_hi, ref.gate_hi), (y.slice_lo, ref.slice_lo)):
        assert_close(a, b, T)


@pytest.mark.parametrize("seed", range(6))
def test_matches_sequential_reference(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    T, n = int(rng.integers(2, 30)), int(rng.integers(1, 4))
    t = random_grid(rng, T)
    truth = Truth(rng, t, n)
    x = fixes(rng, truth, Tube.entire(t, n), count=min(T + 1, 3), tight=False)
    u_lo, u_hi = truth.u_lo - rng.uniform(0, 0.5, (T, n)), truth.u_hi + rng.uniform(0, 0.5, (T, n))
    if seed % 3 == 0:
        u_hi[rng.integers(T)] = INF
    for fw, bw in ((True, True), (True, False), (False, True)):
        y, ref = ctc_deriv(x, u_lo, u_hi, fw, bw), seq_ctc(x, u_lo, u_hi, fw, bw)
        for a, b in ((y.gate_lo, ref.gate_lo), (y.gate_hi, ref.gate_hi), (y.slice_lo, ref.slice_lo),
                     (y.slice_hi, ref.slice_hi)):  # fmt: skip
            assert_close(a, b, T)


def test_cumsum_enclosure_exact_and_tight() -> None:
    d = np.array([[1.0], [2.0], [0.5]])
    lo, hi = cumsum_enclosure(d)
    assert lo.ravel().tolist() == hi.ravel().tolist() == [0.0, 1.0, 3.0, 3.5]
    rng = np.random.default_rng(0)
    d = rng.uniform(-1, 1, (5000, 1)) * 10.0 ** rng.uniform(-8, 8, (5000, 1))
    lo, hi = cumsum_enclosure(d)
    exact, q = [Fraction(0)], Fraction(0)
    for v in d[:, 0]:
        q += Fraction(float(v))
        exact.append(q)
    for k in range(0, 5001, 13):
        assert Fraction(lo[k, 0]) <= exact[k] <= Fraction(hi[k, 0])
    assert (rnd.sub_up(hi, lo) <= 4 * np.spacing(np.abs(hi) + np.abs(lo))).all()  # compensated: ulps


def test_cumsum_enclosure_fallbacks(monkeypatch: pytest.MonkeyPatch) -> None:
    lo, hi = cumsum_enclosure(np.array([[1e308], [1e308], [-1e308]]))
    assert lo[1, 0] == hi[1, 0] == 1e308 and lo[2, 0] == -INF and hi[3, 0] == INF  # overflow: no claim
    rng = np.random.default_rng(1)
    d = rng.normal(size=(3000, 2)) * 10.0 ** rng.uniform(-5, 5, (3000, 2))
    import digslam.observer.tube.ctc as tc

    monkeypatch.setattr(tc.np, "array_equal", lambda a, b: False)  # the a-priori bound path
    lo, hi = cumsum_enclosure(d)
    for i in range(2):
        q = Fraction(0)
        for k in range(3001):
            assert Fraction(lo[k, i]) <= q <= Fraction(hi[k, i])
            q += Fraction(float(d[k, i])) if k < 3000 else 0


def test_contractor_and_idempotent() -> None:
    rng = np.random.default_rng(11)
    T = 50
    t = random_grid(rng, T)
    truth = Truth(rng, t, 2)
    x = fixes(rng, truth, Tube.entire(t, 2), count=5, tight=False)
    y = ctc_deriv(x, truth.u_lo, truth.u_hi)
    assert (y.gate_lo >= x.gate_lo).all() and (y.gate_hi <= x.gate_hi).all()
    assert (y.slice_lo >= x.slice_lo).all() and (y.slice_hi <= x.slice_hi).all()
    z = ctc_deriv(y, truth.u_lo, truth.u_hi)
    assert (z.gate_lo >= y.gate_lo).all() and (z.gate_hi <= y.gate_hi).all()
    for a, b in ((z.gate_lo, y.gate_lo), (z.gate_hi, y.gate_hi), (z.slice_lo, y.slice_lo)):
        assert np.abs(a - b).max() <= 1e-13
    assert (x & y).gate_lo.tolist() == y.gate_lo.tolist()


def test_example_2_9_propagation() -> None:
    """Example 2.9 (Eq. 2.78-2.79): ``[u](t) = 4 sin(t-5) + (t-3.3)[-0.1, 0.1]``, ``x(0) ∈ [-3, 3]``, then
    ``x(t_1) ∈ [2.2, 2.8]`` (``t_1 = 6``: the thesis does not state it) propagated to the whole tube."""
    t = np.linspace(0.0, 10.0, 2001)
    tau = (t[:-1], t[1:])
    s = trig.sin(arith.sub(tau, (np.full(2000, 5.0), np.full(2000, 5.0))))
    e = arith.mul(
        arith.sub(tau, (np.full(2000, 3.3), np.full(2000, 3.3))), (np.full(2000, -0.1), np.full(2000, 0.1))
    )
    u_lo, u_hi = arith.add(arith.mul((np.full(2000, 4.0),) * 2, s), e)
    x = dead_reckoning(t, [-3.0], [3.0], u_lo, u_hi)
    exact_w = 6 + 0.2 * (3.3**2 / 2 + 6.7**2 / 2)  # 6 + 0.2 ∫|τ-3.3| over [0, 10]
    assert exact_w <= x.widths()[-1] <= exact_w + 0.15  # + Σ 4 dt² |cos|: slice pessimism
    k1 = 1200
    assert t[k1] == 6.0
    z = x.copy()
    z.gate_lo[k1], z.gate_hi[k1] = 2.2, 2.8
    y = ctc_deriv(z, u_lo, u_hi)
    assert (y.widths() <= x.widths()).all() and y.widths()[k1] <= 0.6
    # x(0) >= 2.2 - 4(cos 5 - cos 1) - 0.1 ∫_0^6 |τ-3.3|: the backward propagation finds it
    x0_min = 2.2 - 4 * (math.cos(5) - math.cos(1)) - 0.1 * (3.3**2 / 2 + 2.7**2 / 2)
    assert x0_min - 0.06 <= y.gate_lo[0, 0] <= x0_min  # - Σ 2 dt² |cos| and y.gate_hi[0, 0] == 3.0
    # a true trajectory: x0 = 2.8, error input 0.1·sign(τ - 3.3)
    ts = np.linspace(0, 10, 3001)
    integral = np.where(ts < 3.3, 3.3 * ts - ts**2 / 2, 3.3**2 / 2 + (ts - 3.3) ** 2 / 2)
    xs = 2.8 + 4 * (np.cos(-5) - np.cos(ts - 5)) + 0.1 * integral
    assert y.contains(ts, xs).all() and x.contains(ts, xs).all()


def test_pinning_final_gate_shrinks_earlier_gates() -> None:
    t = np.linspace(0, 100, 1001)
    u = np.stack([np.cos(t[:-1] / 10), np.sin(t[:-1] / 7)], axis=1)
    x = dead_reckoning(t, [0, 0], [0, 0], u - 0.05, u + 0.05)
    mid = (x.gate_lo[-1] + x.gate_hi[-1]) / 2
    z = x.copy()
    z.gate_lo[-1], z.gate_hi[-1] = mid - 0.1, mid + 0.1
    y = ctc_deriv(z, u - 0.05, u + 0.05)
    assert (y.widths() <= x.widths()).all() and (y.widths()[520:] < x.widths()[520:]).all()
    assert y.widths().max() <= 0.1 * 100 / 2 + 0.2 + 1e-9  # the widest is mid-way: both ends known


def test_heading_from_gyro_exact_rate_on_bound() -> None:
    t = np.linspace(0.0, 120.0, 1201)
    rate = 0.1 + 0.001
    psi = heading_from_gyro(t, 0.0, 0.0, np.full(1200, 0.1 - 0.001), np.full(1200, rate))
    assert psi.n == 1 and psi.T == 1200
    for k in range(0, 1201, 10):
        q = Fraction(rate) * Fraction(float(t[k]))
        assert inside(psi.gate_lo[k, 0], psi.gate_hi[k, 0], q)
    assert psi.widths()[-1] == pytest.approx(0.002 * 120, rel=1e-9)


def test_heading_from_compass_fusion() -> None:
    rng = np.random.default_rng(5)
    t = np.arange(0, 601) * 0.1
    truth = 0.3 * np.sin(0.5 * t)
    meas = truth + rng.uniform(-0.005, 0.005, t.size)
    c_lo, c_hi = meas - 0.01, meas + 0.01
    tau = (t[:-1], t[1:])
    w = arith.mul((np.full(600, 0.15),) * 2, trig.cos(arith.mul((np.full(600, 0.5),) * 2, tau)))
    w_lo, w_hi = w[0] - 0.001, w[1] + 0.001
    compass = heading_from_compass(t, c_lo, c_hi)
    assert compass.slice_lo[:, 0].tolist() == np.minimum(c_lo[:-1], c_lo[1:]).tolist()
    fused = heading_from_compass(t, c_lo, c_hi, w_lo, w_hi)
    assert (fused.widths() <= compass.widths()).all()
    assert fused.widths().mean() < 0.75 * compass.widths().mean()
    ts = np.linspace(0, 60, 20011)
    assert fused.contains(ts, 0.3 * np.sin(0.5 * ts)).all()
    with pytest.raises(ValueError, match="yaw_rate_lo"):
        heading_from_compass(t, c_lo, c_hi, w_lo)


def test_inconsistent_data_gives_empty_tube() -> None:
    t = np.arange(11.0)
    x = dead_reckoning(t, [0.0], [0.0], np.ones(10), np.ones(10))
    assert not x.is_empty() and x.first_empty() is None
    z = x.copy()
    z.gate_lo[5], z.gate_hi[5] = 100.0, 101.0  # x(5) = 5 is forced by the dynamics
    y = ctc_deriv(z, np.ones(10), np.ones(10))
    assert y.is_empty() and y.first_empty() == 0 and y.inconsistent_at == 5
    late = x.copy()
    late.gate_lo[8], late.gate_hi[8] = 8.5, 9.0  # forward pass finds it at gate 8
    assert ctc_deriv(late, np.ones(10), np.ones(10)).inconsistent_at == 8
    assert x.inconsistent_at is None and ctc_deriv(x, np.ones(10), np.ones(10)).inconsistent_at is None
    assert (y.gate_lo == INF).all() and (y.slice_hi == -INF).all()
    empty_gate = Tube(t, np.where(t[:, None] == 3, INF, -INF), np.where(t[:, None] == 3, -INF, INF))
    assert empty_gate.first_empty() == 3  # the hull slices next to it are not empty
    assert ctc_deriv(empty_gate, np.ones(10), np.ones(10)).first_empty() == 0
    assert ctc_deriv(empty_gate, np.ones(10), np.ones(10)).inconsistent_at == 3
    u_lo = np.ones(10)
    u_lo[4] = INF  # [+inf, +inf]: no derivative
    assert ctc_deriv(Tube.entire(t, 1), u_lo, np.full(10, INF)).is_empty()


def test_tube_api() -> None:
    t = np.array([0.0, 1.0, 3.0])
    x = Tube(t, [[0, 1], [1, 2], [2, 5]], [[1, 2], [2, 3], [4, 6]])
    assert (x.n, x.T, x.dt.tolist()) == (2, 2, [1.0, 2.0])
    assert x.slice_lo.tolist() == [[0, 1], [1, 2]] and x.slice_hi.tolist() == [[2, 3], [4, 6]]
    lo, hi = x(1.0)
    assert lo.tolist() == [1, 2] and hi.tolist() == [2, 3]
    lo, hi = x(2.0)
    assert lo.tolist() == [1, 2] and hi.tolist() == [4, 6]
    lo, hi = x(np.array([0.0, 0.5, 3.0]))
    assert lo.shape == (3, 2) and lo[2].tolist() == [2, 5]
    assert [v.tolist() for v in x.eval(0.5, 1.0)] == [[0, 1], [2, 3]]
    assert [v.tolist() for v in x.eval(0.0, 3.0)] == [[0, 1], [4, 6]]
    assert [v.tolist() for v in x.eval(1.0, 1.0)] == [[1, 2], [2, 3]]
    assert x.widths().tolist() == [1, 1, 2]
    assert x.contains([0.5, 1.0, 3.0], [[0.5, 1.5], [2.5, 2.0], [3.0, 5.5]]).tolist() == [True, False, True]
    y = x.copy()
    y.gate_lo[0, 0] = 0.5
    assert x.gate_lo[0, 0] == 0.0 and (x & y).gate_lo[0, 0] == 0.5
    e = Tube.entire(t, 3)
    assert e.n == 3 and (e.gate_lo == -INF).all() and (e.slice_hi == INF).all()
    assert "T=2" in repr(x)
    one = Tube(t, [0, 1, 2], [1, 2, 3])
    assert one.n == 1 and one.gate_lo.shape == (3, 1)


def test_save_load_roundtrip(tmp_path: object) -> None:
    t = np.linspace(0, 1, 11)
    x = dead_reckoning(t, [0, 1], [0, 1], np.ones((10, 2)), np.full((10, 2), 2.0))
    path = tmp_path / "tube.npz"  # type: ignore[operator]
    x.save_npz(path)
    y = Tube.load_npz(path)
    for a in ("t", "gate_lo", "gate_hi", "slice_lo", "slice_hi"):
        assert np.array_equal(getattr(x, a), getattr(y, a))


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: Tube([0, 1, 1], [0, 0, 0], [1, 1, 1]), "t"),
        (lambda: Tube([0], [0], [1]), "t"),
        (lambda: Tube([0, 1, 2], [0, 0], [1, 1]), "gate"),
        (lambda: Tube([0, 1, 2], [0, 2, 0], [1, 1, 1]), "gate"),
        (lambda: Tube([0, 1, 2], [0, np.nan, 0], [1, 1, 1]), "gate"),
        (lambda: Tube([0, 1, 2], [0, 0, 0], [1, 1, 1], [[0]], [[1]]), "slice"),
        (lambda: Tube([0, 1, 2], [0, 0, 0], [1, 1, 1], [[0], [0]]), "slice_lo"),
        (lambda: Tube.entire([0, 1], 0), "n"),
        (lambda: ctc_deriv(Tube.entire([0, 1, 2], 2), np.zeros((3, 2)), np.zeros((3, 2))), "u"),
        (lambda: ctc_deriv(Tube.entire([0, 1, 2], 2), np.ones((2, 2)), np.zeros((2, 2))), "u"),
        (lambda: ctc_deriv("tube", np.ones((2, 2)), np.zeros((2, 2))), "x"),  # type: ignore[arg-type]
        (lambda: Tube.entire([0, 1], 1) & Tube.entire([0, 2], 1), "other"),
        (lambda: Tube.entire([0, 1], 1) & Tube.entire([0, 1], 2), "other"),
        (lambda: Tube.entire([0, 1], 1)(2.0), "t"),
        (lambda: Tube.entire([0, 1], 1).eval(0.8, 0.2), "ta"),
        (lambda: Tube.entire([0, 1], 2).contains([0.5], [[0.0]]), "x_samples"),
        (lambda: unicycle_velocity([1, 1], [2, 2], [0], [1]), "heading"),
        (lambda: unicycle_velocity([3, 1], [2, 2], [0, 0], [1, 1]), "speed"),
        (lambda: body_velocity(np.zeros(2), np.zeros(2), [0, 0], [1, 1]), "v"),
        (lambda: dead_reckoning([0, 1], [0, 0], [1], np.zeros((1, 2)), np.zeros((1, 2))), "x0"),
        (lambda: heading_from_gyro([0, 1], 1.0, 0.0, [0.0], [0.0]), "psi0"),
    ],
)
def test_bad_input_names_argument(call: object, name: str) -> None:
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        call()  # type: ignore[operator]


@settings(max_examples=60, deadline=None)
@given(
    v=st.tuples(st.floats(-3, 5), st.floats(0, 3)),
    psi=st.tuples(st.floats(-20, 20), st.floats(0, 4)),
    frac=st.lists(st.sampled_from([0.0, 1.0, 0.5, 0.25, 0.9]), min_size=2, max_size=2),
)
def test_unicycle_velocity_contains_point_images(v: tuple, psi: tuple, frac: list) -> None:
    v_lo, v_hi = v[0], v[0] + v[1]
    p_lo, p_hi = psi[0], psi[0] + psi[1]
    (u_lo, u_hi) = unicycle_velocity([v_lo], [v_hi], [p_lo], [p_hi])
    (b_lo, b_hi) = body_velocity([[v_lo, 0.0]], [[v_hi, 0.0]], [p_lo], [p_hi])
    rng = np.random.default_rng(int(1e6 * abs(v[0] + psi[0])) % 2**32)
    vs = [v_lo, v_hi, v_lo + frac[0] * (v_hi - v_lo), *rng.uniform(v_lo, v_hi, 3)]
    ps = [p_lo, p_hi, p_lo + frac[1] * (p_hi - p_lo), *rng.uniform(p_lo, p_hi, 3)]
    with mpmath.workdps(40):
        for vv in vs:
            for pp in ps:
                if not (v_lo <= vv <= v_hi and p_lo <= pp <= p_hi):
                    continue
                img = (
                    mpmath.mpf(vv) * mpmath.cos(mpmath.mpf(pp)),
                    mpmath.mpf(vv) * mpmath.sin(mpmath.mpf(pp)),
                )
                for lo, hi in ((u_lo, u_hi), (b_lo, b_hi)):
                    for i in range(2):
                        assert mpmath.mpf(lo[0, i]) <= img[i] <= mpmath.mpf(hi[0, i])


def test_unicycle_dead_reckoning_sound() -> None:
    """Heading tube from a gyro, velocity boxes on its slices, dead reckoning: the truth stays inside."""
    t = np.arange(0, 3001) * 0.1
    w = lambda s: 0.05 * np.sin(0.02 * s)  # noqa: E731
    psi_true = lambda s: 2.5 * (1 - np.cos(0.02 * s))  # noqa: E731  ∫ w
    tau = (t[:-1], t[1:])
    wb = arith.mul((np.full(3000, 0.05),) * 2, trig.sin(arith.mul((np.full(3000, 0.02),) * 2, tau)))
    psi = heading_from_gyro(t, 0.0, 0.0, wb[0] - 0.001, wb[1] + 0.001)
    u_lo, u_hi = unicycle_velocity(
        np.full(3000, 0.999), np.full(3000, 1.001), psi.slice_lo[:, 0], psi.slice_hi[:, 0]
    )
    x = dead_reckoning(t, [0, 0], [0, 0], u_lo, u_hi)
    fine = np.linspace(0, 300, 300_001)  # trapezoid: error ~1e-9, far inside the tube
    ps = psi_true(fine)
    dx = np.concatenate([[0], np.cumsum((np.cos(ps[1:]) + np.cos(ps[:-1])) / 2 * np.diff(fine))])
    dy = np.concatenate([[0], np.cumsum((np.sin(ps[1:]) + np.sin(ps[:-1])) / 2 * np.diff(fine))])
    assert psi.contains(fine[::7], ps[::7]).all() and w(0.0) == 0.0
    assert x.contains(fine[::7], np.stack([dx, dy], axis=1)[::7]).all()


def test_example_tube_dead_reckoning() -> None:
    from example_loader import load

    res = load("tube_dead_reckoning").run(out=None, minutes=2.0)
    assert res["truth_inside"] and res["T"] == 1200
    assert res["contracted_width_max"] <= res["dead_reckoning_width_final"]  # fixes ±0.5 m: no gain in 2 min
    assert res["heading_width_max"] <= 0.002 + 1e-12 and res["heading_width_gyro_only_final"] > 0.2


@settings(max_examples=80, deadline=None)
@given(
    v1=st.tuples(st.floats(-3, 5), st.floats(0, 3)),
    v2=st.tuples(st.floats(-2, 2), st.floats(0, 2)),
    psi=st.tuples(st.floats(-20, 20), st.floats(0, 4)),
    seed=st.integers(0, 2**32 - 1),
)
def test_body_velocity_contains_rotated_points(v1: tuple, v2: tuple, psi: tuple, seed: int) -> None:
    """``R(psi) v`` (Eq. 3.59, 6.12, B.20) for sampled ``psi``, ``v = (v_1, v_2)`` (corners included) lies in
    the box of :func:`body_velocity` (mpmath at 40 digits)."""
    lo = np.array([[v1[0], v2[0]]])
    hi = np.array([[v1[0] + v1[1], v2[0] + v2[1]]])
    p_lo, p_hi = psi[0], psi[0] + psi[1]
    u_lo, u_hi = body_velocity(lo, hi, [p_lo], [p_hi])
    rng = np.random.default_rng(seed)
    pts = [(a, b, p) for a in (lo[0, 0], hi[0, 0]) for b in (lo[0, 1], hi[0, 1]) for p in (p_lo, p_hi)]
    pts += list(zip(rng.uniform(lo[0, 0], hi[0, 0], 12), rng.uniform(lo[0, 1], hi[0, 1], 12),
                    rng.uniform(p_lo, p_hi, 12), strict=True))  # fmt: skip
    with mpmath.workdps(40):
        for a, b, p in pts:
            if not (lo[0, 0] <= a <= hi[0, 0] and lo[0, 1] <= b <= hi[0, 1] and p_lo <= p <= p_hi):
                continue
            c, s = mpmath.cos(mpmath.mpf(p)), mpmath.sin(mpmath.mpf(p))
            img = (mpmath.mpf(a) * c - mpmath.mpf(b) * s, mpmath.mpf(a) * s + mpmath.mpf(b) * c)
            for i in range(2):
                assert mpmath.mpf(u_lo[0, i]) <= img[i] <= mpmath.mpf(u_hi[0, i])


def test_body_velocity_without_lateral_is_the_unicycle_to_the_bit() -> None:
    """Rows with ``[v_2] = [0, 0]`` are :func:`unicycle_velocity` bit for bit, signs of zero included (the
    natural form would turn a ``-0.0`` bound into ``+0.0``), whatever the other rows hold."""
    rng = np.random.default_rng(3)
    n = 4000
    v = np.sort(rng.uniform(-2, 2, (2, n)), axis=0)
    v[:, :500] = 0.0  # zero speeds: products -0.0 against negative cos/sin
    v[:, 500:1000] = np.sort(rng.choice([-1.0, 0.0, 1.0], (2, 500)), axis=0)
    p = np.sort(rng.uniform(-7, 7, (2, n)), axis=0)
    uni = unicycle_velocity(v[0], v[1], p[0], p[1])
    lat = np.zeros((2, n))
    got = body_velocity(np.stack([v[0], lat[0]], 1), np.stack([v[1], lat[1]], 1), p[0], p[1])
    assert all(a.tobytes() == b.tobytes() for a, b in zip(got, uni, strict=True))
    lat[:, ::2] = [[-0.1], [0.2]]  # mixed: the unicycle rows unchanged, the others wider
    mix = body_velocity(np.stack([v[0], lat[0]], 1), np.stack([v[1], lat[1]], 1), p[0], p[1])
    for a, b in zip(mix, uni, strict=True):
        assert a[1::2].tobytes() == b[1::2].tobytes()
    assert np.all(mix[0][::2] <= uni[0][::2]) and np.all(mix[1][::2] >= uni[1][::2])
