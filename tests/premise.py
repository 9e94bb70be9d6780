"""The premise, recomputed: every recorded quantity of an env episode against an independent exact truth.

The guarantee of the observers holds *if* every recorded interval contains the truth. This helper recomputes
the truth without the simulator's code and checks that premise step by step:

* **Motion** in mpmath (:data:`PREC` bits): the true pose is the exact chain of unicycle arcs described by
  ``truth.pieces`` from the (exact) reset pose. Over a piece ``(v, tau, theta_end)`` the heading moves
  linearly from ``theta_start`` to ``theta_end`` and ``x' = x + v tau sinc(D/2) cos(theta_start + D/2)``,
  ``y' = y + v tau sinc(D/2) sin(theta_start + D/2)`` with ``D = theta_end - theta_start``; its yaw rate
  is ``D / tau``. The float pose the simulator carries must lie within ``truth.pose_error`` of the exact
  one (per coordinate), its heading must equal the exact heading, the taus must sum exactly to the record's
  time step, the speed interval must contain every piece's speed and the yaw-rate interval every piece's
  yaw rate (pieces of positive duration), the heading interval the exact heading.
* **Ranges** by brute-force geometry written here (not ``envs/geometry_jit``): the distance from the
  exact pose to the nearest point of the world's edges inside each closed cone (direction
  ``heading + alpha[s]``, half-aperture ``gamma[s]``; ``gamma >= pi`` is the whole plane), in mpmath from
  the candidates where the minimum of the distance over an edge's part inside a cone can lie (the foot of the
  perpendicular, the endpoints inside the cone, the crossings with the cone's two boundary rays), edges
  taken in order of a lower bound of their distance (branch and bound), plus a dense sampling of every
  edge within reach as a cross-check of that computation. An echo interval must contain the exact distance;
  ``no_echo`` claims the exact distance exceeds ``r_max``. Readings flagged ``outlier`` are exempt (at most
  ``max_outliers`` of them per step when given).
* **pymunk motion** (``truth.states`` non-empty): the truth is the piecewise-linear path through the stored
  substep states ``(x, y, angle)`` (floats, exact), each substep lasting ``truth.taus[j]``. The checker
  requires the first state to be the previous exact pose, the last the float pose (``pose_error = 0``), the
  taus to be positive and to sum exactly to the record's time step, and, in exact arithmetic, every
  substep's yaw rate ``(a_{j+1} - a_j) / tau_j`` (``Fraction``) inside ``record.yaw_rate`` and its
  body-frame velocity ``R(-psi) u_j``, ``u_j = (p_{j+1} - p_j) / tau_j`` (``Fraction``), inside
  ``record.speed x record.lateral`` for every heading ``psi`` between ``a_j`` and ``a_{j+1}``: the extremes
  of each component over that range lie at its ends or where ``psi - atan2(u_y, u_x)`` is a multiple of
  ``pi/2`` (:func:`velocity_extremes`, mpmath). The odometry increment ``record.mean_velocity`` must contain
  ``R(-a_0) (p_S - p_0) / dt`` (:func:`mean_velocity_exact`, mpmath). A unicycle step (``truth.pieces``) has
  no lateral velocity: ``record.lateral`` must contain 0; its ``mean_velocity`` must be unmeasured.
* **The disc** (when ``radius`` is given, pymunk steps): the robot's disc of that radius centred anywhere on
  a substep segment keeps off every edge: the exact (``Fraction``) distance between the segment and each
  edge is at least ``radius`` (:func:`segment_distance2`; edges farther than ``radius + 0.01`` in floats
  are screened out).

Use :class:`PremiseChecker` (``reset`` then ``step`` with each ``(record, truth)``), or :func:`check_episode`
to drive an env through actions; both raise :class:`PremiseViolation` naming the step and the quantity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np

#: Working precision (bits) of the exact recomputation.
PREC = 200


class PremiseViolation(AssertionError):
    """A recorded interval misses the recomputed truth."""


def pieces(truth: Any) -> np.ndarray:
    """The step's pieces ``(2, 3)``, rows ``(v, tau, theta_end)`` (``truth.pieces``)."""
    return np.asarray(truth.pieces, dtype=np.float64)


def path(truth: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The step's pymunk path ``(states (S + 1, 3), taus (S,))``, or None for a unicycle step."""
    states = getattr(truth, "states", None)
    if states is None or np.size(states) == 0:
        return None
    return np.asarray(states, dtype=np.float64), np.asarray(truth.taus, dtype=np.float64)


def mpf(v: float) -> mpmath.mpf:
    """The float ``v`` as an exact mpmath number (every float64 is exact at :data:`PREC` bits)."""
    with mpmath.workprec(PREC):
        return mpmath.mpf(float(v))


# --- exact motion ------------------------------------------------------------------------------------------
def arc_exact(x: Any, y: Any, th0: float, v: float, tau: float, th1: float) -> tuple[Any, Any]:
    """Exact end point of one piece (heading linear from ``th0`` to ``th1`` over ``tau`` at speed ``v``)."""
    with mpmath.workprec(PREC):
        d = mpmath.mpf(th1) - mpmath.mpf(th0)
        half = d / 2
        s = mpmath.mpf(v) * mpmath.mpf(tau) * mpmath.sinc(half)
        mid = mpmath.mpf(th0) + half
        return x + s * mpmath.cos(mid), y + s * mpmath.sin(mid)


@dataclass
class ExactPose:
    """The exact pose: position in mpmath, heading a float (exact by the interface)."""

    x: Any
    y: Any
    th: float

    def floats(self) -> np.ndarray:
        """Nearest float64 ``(x, y, th)``."""
        return np.array([float(self.x), float(self.y), self.th])


def mean_velocity_exact(states: np.ndarray, taus: np.ndarray) -> tuple[Any, Any]:
    """The odometry increment of a pymunk path, in mpmath: ``R(-a_0) (p_S - p_0) / dt``, ``dt = sum(taus)``
    (exact), i.e. ``(1/dt) ∫ R(psi(t) - a_0) v(t) dt`` along the piecewise-linear path."""
    dt = sum(Fraction(float(t)) for t in taus)
    return increment(mpf(states[0, 0]), mpf(states[0, 1]), float(states[0, 2]), mpf(states[-1, 0]),
                     mpf(states[-1, 1]), dt)  # fmt: skip


def increment(x0: Any, y0: Any, th0: float, x1: Any, y1: Any, dt: Fraction) -> tuple[Any, Any]:
    """``R(-th0) (p_1 - p_0) / dt`` in mpmath (forward, leftward)."""
    with mpmath.workprec(PREC):
        t = mpmath.mpf(dt.numerator) / dt.denominator
        c, s = mpmath.cos(mpf(th0)), mpmath.sin(mpf(th0))
        dx, dy = x1 - x0, y1 - y0
        return (c * dx + s * dy) / t, (c * dy - s * dx) / t


def velocity_extremes(ux: Fraction, uy: Fraction, a0: float, a1: float) -> tuple[Any, Any, Any, Any]:
    """``(min v1, max v1, min v2, max v2)`` (mp, :data:`PREC` bits) of the body-frame velocity
    ``v1 = cos(psi) ux + sin(psi) uy``, ``v2 = cos(psi) uy - sin(psi) ux`` over ``psi`` between ``a0`` and
    ``a1``: at the ends, or where ``psi - atan2(uy, ux)`` is a multiple of ``pi/2`` inside."""
    with mpmath.workprec(PREC):
        x, y = mpmath.mpf(ux.numerator) / ux.denominator, mpmath.mpf(uy.numerator) / uy.denominator
        lo, hi = mpmath.mpf(min(a0, a1)), mpmath.mpf(max(a0, a1))
        cands = [lo, hi]
        if x != 0 or y != 0:
            phi = mpmath.atan2(y, x)
            k = mpmath.ceil((lo - phi) / (mpmath.pi / 2))
            while phi + k * mpmath.pi / 2 <= hi:
                cands.append(phi + k * mpmath.pi / 2)
                k += 1
        v1 = [mpmath.cos(p) * x + mpmath.sin(p) * y for p in cands]
        v2 = [mpmath.cos(p) * y - mpmath.sin(p) * x for p in cands]
        return min(v1), max(v1), min(v2), max(v2)


def _point_segment2(q: tuple, a: tuple, b: tuple) -> Fraction:
    dx, dy = b[0] - a[0], b[1] - a[1]
    dd = dx * dx + dy * dy
    t = Fraction(0)
    if dd:
        t = min(max(((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / dd, Fraction(0)), Fraction(1))
    ex, ey = a[0] + t * dx - q[0], a[1] + t * dy - q[1]
    return ex * ex + ey * ey


def _orient(a: tuple, b: tuple, c: tuple) -> int:
    d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (d > 0) - (d < 0)


def segment_distance2(p0: Any, p1: Any, e0: Any, e1: Any) -> Fraction:
    """Exact squared distance between the closed segments ``p0 p1`` and ``e0 e1`` (float points): 0 when
    they cross, else the least endpoint-to-segment distance."""
    p0, p1, e0, e1 = (tuple(Fraction(float(c)) for c in q) for q in (p0, p1, e0, e1))
    if _orient(e0, e1, p0) * _orient(e0, e1, p1) < 0 and _orient(p0, p1, e0) * _orient(p0, p1, e1) < 0:
        return Fraction(0)
    return min(_point_segment2(p0, e0, e1), _point_segment2(p1, e0, e1), _point_segment2(e0, p0, p1),
               _point_segment2(e1, p0, p1))  # fmt: skip


# --- exact cone distances ----------------------------------------------------------------------------------
def _plain_dist(px: float, py: float, e: np.ndarray) -> np.ndarray:
    """Float distance from ``(px, py)`` to each edge (``(E, 4)``), clamped foot."""
    ax, ay = e[:, 0] - px, e[:, 1] - py
    dx, dy = e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]
    dd = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dd > 0, np.clip(-(ax * dx + ay * dy) / dd, 0.0, 1.0), 0.0)
    return np.hypot(ax + t * dx, ay + t * dy)


def _edge_cone_exact(px: Any, py: Any, e: np.ndarray, phi: Any, gamma: float) -> Any:
    """Exact (mp) distance from ``(px, py)`` to the part of edge ``e`` inside the closed cone ``(phi, gamma)``;
    ``inf`` if the edge misses the cone."""
    inf = mpmath.inf
    ax, ay = mpmath.mpf(float(e[0])) - px, mpmath.mpf(float(e[1])) - py
    bx, by = mpmath.mpf(float(e[2])) - px, mpmath.mpf(float(e[3])) - py
    dx, dy = bx - ax, by - ay
    dd = dx * dx + dy * dy
    whole = gamma >= math.pi
    ux, uy = mpmath.cos(phi), mpmath.sin(phi)
    cg = mpmath.cos(mpmath.mpf(gamma))

    def inside(qx: Any, qy: Any) -> bool:
        return whole or ux * qx + uy * qy >= mpmath.sqrt(qx * qx + qy * qy) * cg

    best = inf
    pts = [(ax, ay), (bx, by)]
    if dd > 0:
        t = -(ax * dx + ay * dy) / dd
        if 0 <= t <= 1:
            pts.append((ax + t * dx, ay + t * dy))
    for qx, qy in pts:
        if inside(qx, qy):
            best = min(best, mpmath.sqrt(qx * qx + qy * qy))
    if whole:
        return best
    cross = ax * dy - ay * dx
    for sgn in (-1, 1):
        wa = phi + sgn * mpmath.mpf(gamma)
        wx, wy = mpmath.cos(wa), mpmath.sin(wa)
        den = wx * dy - wy * dx
        if den == 0:
            continue
        r = cross / den
        sp = (wy * ax - wx * ay) / den
        if r >= 0 and 0 <= sp <= 1:
            best = min(best, r)
    return best


def _sampled_cone_min(px: float, py: float, e: np.ndarray, phi: float, gamma: float, n: int = 257) -> float:
    """Float minimum distance over ``n`` samples per edge that lie inside the cone with a margin (an upper
    bound of the exact distance, up to float rounding)."""
    if not len(e):
        return math.inf
    s = np.linspace(0.0, 1.0, n)
    qx = e[:, None, 0] + s[None, :] * (e[:, None, 2] - e[:, None, 0]) - px
    qy = e[:, None, 1] + s[None, :] * (e[:, None, 3] - e[:, None, 1]) - py
    r = np.hypot(qx, qy)
    if gamma < math.pi:
        ang = np.abs(np.mod(np.arctan2(qy, qx) - phi + math.pi, 2 * math.pi) - math.pi)
        r = np.where(ang <= gamma - 1e-9, r, np.inf)
    return float(r.min())


def cone_distances(pose: ExactPose, alpha: np.ndarray, gamma: np.ndarray, edges: np.ndarray, cap: np.ndarray,
                   dense: bool = True) -> list[Any]:  # fmt: skip
    """Exact distance (mp) from ``pose`` to the nearest edge point in each closed cone, or ``inf`` when none
    lies within ``cap[s]`` (branch and bound over the edges in order of a float lower bound)."""
    with mpmath.workprec(PREC):
        fx, fy = float(pose.x), float(pose.y)
        d = _plain_dist(fx, fy, edges)
        lb = d * (1 - 1e-12) - 1e-9  # a safe lower bound of each edge's exact distance from the exact pose
        order = np.argsort(lb)
        out = []
        for s in range(len(alpha)):
            phi = mpmath.mpf(pose.th) + mpmath.mpf(alpha[s])
            best = mpmath.inf
            for k in order:
                if lb[k] > cap[s] or (best < mpmath.inf and lb[k] > best):
                    break
                best = min(best, _edge_cone_exact(pose.x, pose.y, edges[k], phi, float(gamma[s])))
            if best > cap[s]:
                best = mpmath.inf
            if dense:
                near = edges[d <= float(cap[s]) + 1.0]
                samp = _sampled_cone_min(fx, fy, near, float(phi), float(gamma[s]))
                if samp <= cap[s] and not best <= samp + 1e-9:
                    raise PremiseViolation(
                        f"self-check: sampled cone distance {samp} below the exact {best} (sensor {s})"
                    )
            out.append(best)
        return out


# --- the checker -------------------------------------------------------------------------------------------
def _within(v: Any, iv: np.ndarray) -> bool:
    with mpmath.workprec(PREC):
        return mpmath.mpf(float(iv[0])) <= v <= mpmath.mpf(float(iv[1]))


class PremiseChecker:
    """Step-by-step recomputation of an episode's truth and check of its record.

    Args:
        edges: The world's edges ``(E, 4)`` (``env.unwrapped.world.edges``).
        dense: Also cross-check the exact cone distances by dense sampling.
        max_outliers: If given, at most this many readings per step may be flagged ``outlier``.
        radius: If given, check that the robot's disc of this radius keeps off every edge along each pymunk
            substep segment.
        ranges: Check the range readings (the expensive part); False checks the motion only.
    """

    def __init__(self, edges: np.ndarray, dense: bool = True, max_outliers: int | None = None,
                 radius: float | None = None, ranges: bool = True) -> None:  # fmt: skip
        self.edges = np.ascontiguousarray(edges, dtype=np.float64).reshape(-1, 4)
        self.dense, self.max_outliers = dense, max_outliers
        self.radius, self.check_ranges = radius, ranges
        #: pymunk substeps checked so far.
        self.substeps = 0
        self.pose: ExactPose | None = None
        self.t = 0.0
        self.k = 0
        #: Per step: the exact pose (floats) and the exact ranges (floats; inf where none within the cap).
        self.poses: list[np.ndarray] = []
        self.ranges: list[np.ndarray] = []
        #: The same exactly: :class:`ExactPose` and mp distances.
        self.exact_poses: list[ExactPose] = []
        self.exact_ranges: list[list[Any]] = []
        #: The pieces of each step after reset (unicycle) or its path ``(states, taus)`` (pymunk).
        self.pieces: list[np.ndarray] = []
        self.paths: list[tuple[np.ndarray, np.ndarray]] = []

    def fail(self, msg: str) -> None:
        raise PremiseViolation(f"step {self.k}: {msg}")

    def reset(self, record: Any, truth: Any) -> ExactPose:
        """Record 0: the reset pose is exact; the robot is at rest."""
        self.k = 0
        p = np.asarray(truth.pose, dtype=np.float64)
        self.pose = ExactPose(mpf(p[0]), mpf(p[1]), float(p[2]))
        pth = path(truth)
        if pth is not None:
            states, taus = pth
            if np.any(states != p[None]) or np.any(taus != 0):
                self.fail(
                    f"reset: path {states.tolist()}, {taus.tolist()} should be at rest, at {p.tolist()}"
                )
        else:
            seg = pieces(truth)
            if seg.shape != (2, 3):
                self.fail(f"pieces: expected shape (2, 3), got {seg.shape}")
            if np.any(seg[:, :2] != 0) or np.any(seg[:, 2] != p[2]):
                self.fail(f"reset: pieces {seg.tolist()} should be at rest, at the start heading {p[2]!r}")
        self.t, self.substeps = float(record.t), 0
        self.poses, self.ranges, self.exact_poses, self.exact_ranges, self.pieces = [], [], [], [], []
        self.paths = []
        for name in ("speed", "yaw_rate", "lateral"):
            if not _within(mpf(0.0), getattr(record, name)):
                self.fail(f"{name} interval {getattr(record, name).tolist()} misses 0 (robot at rest)")
        self._common(record, truth)
        return self.pose

    def step(self, record: Any, truth: Any) -> ExactPose:
        """One step: advance the exact pose along ``truth.pieces`` (unicycle) or ``truth.states`` (pymunk)
        and check ``record``."""
        assert self.pose is not None, "reset first"
        self.k += 1
        if float(truth.t) != float(record.t):
            self.fail(f"truth.t {float(truth.t)!r} != record.t {float(record.t)!r}")
        pth = path(truth)
        if pth is not None:
            self._step_path(record, *pth)
            self._common(record, truth)
            return self.pose
        if not _within(mpf(0.0), record.lateral):
            self.fail(f"lateral interval {record.lateral.tolist()} misses 0 (a unicycle does not slip)")
        seg = pieces(truth)
        if seg.shape != (2, 3) or not np.all(np.isfinite(seg)):
            self.fail(f"pieces: expected finite (2, 3), got {seg!r}")
        self.pieces.append(seg)
        t = float(record.t)
        with mpmath.workprec(PREC):
            dt = mpmath.mpf(t) - mpmath.mpf(self.t)
            if np.any(seg[:, 1] < 0) or mpmath.mpf(seg[0, 1]) + mpmath.mpf(seg[1, 1]) != dt:
                self.fail(f"piece durations {seg[:, 1].tolist()} do not sum exactly to t_k - t_(k-1) = {dt}")
            x, y, th = self.pose.x, self.pose.y, self.pose.th
            for v, tau, th1 in seg.tolist():
                if tau > 0:
                    rate = (mpmath.mpf(th1) - mpmath.mpf(th)) / mpmath.mpf(tau)
                    if not _within(mpmath.mpf(v), record.speed):
                        self.fail(f"speed interval {record.speed.tolist()} misses the piece speed {v!r}")
                    if not _within(rate, record.yaw_rate):
                        self.fail(
                            f"yaw-rate interval {record.yaw_rate.tolist()} misses the piece yaw rate "
                            f"{mpmath.nstr(rate, 20)} (theta {th!r} -> {th1!r} over {tau!r} s)"
                        )
                elif th1 != th:
                    self.fail(f"a piece of zero duration turns the heading {th!r} -> {th1!r}")
                x, y = arc_exact(x, y, th, v, tau, th1)
                th = th1
        self._check_mean(record, self.pose, ExactPose(x, y, th), Fraction(t) - Fraction(self.t))
        self.pose = ExactPose(x, y, th)
        self.t = t
        self._common(record, truth)
        return self.pose

    def _step_path(self, record: Any, states: np.ndarray, taus: np.ndarray) -> None:
        """A pymunk step: the path starts at the exact pose, lasts exactly the record's time step, and every
        substep's motion lies inside the record."""
        assert self.pose is not None
        n = len(taus)
        if states.shape != (n + 1, 3) or not np.all(np.isfinite(states)) or not np.all(np.isfinite(taus)):
            self.fail(
                f"path: expected finite states (S + 1, 3) and taus (S,), got {states.shape}, {taus.shape}"
            )
        start = self.pose
        with mpmath.workprec(PREC):
            if not (
                mpf(states[0, 0]) == start.x and mpf(states[0, 1]) == start.y and states[0, 2] == start.th
            ):
                self.fail(
                    f"path starts at {states[0].tolist()}, not at the previous pose {start.floats().tolist()}"
                )
        t = float(record.t)
        dt = Fraction(t) - Fraction(self.t)
        if np.any(taus <= 0) or sum(Fraction(float(v)) for v in taus) != dt:
            self.fail(
                f"substep durations {taus.tolist()} do not sum exactly to t_k - t_(k-1) = {float(dt)!r}"
            )
        self.check_path(states, taus, record)
        end = ExactPose(mpf(states[-1, 0]), mpf(states[-1, 1]), float(states[-1, 2]))
        self._check_mean(record, start, end, dt)
        self.paths.append((states, taus))
        self.pose = ExactPose(mpf(states[-1, 0]), mpf(states[-1, 1]), float(states[-1, 2]))
        self.t = t

    def _check_mean(self, record: Any, start: ExactPose, end: ExactPose, dt: Fraction) -> None:
        """The odometry increment ``record.mean_velocity`` (when present) contains ``R(-th_0) (p_1 - p_0)
        / dt`` between the exact poses."""
        mean = getattr(record, "mean_velocity", None)
        if mean is None:
            return
        exact = increment(start.x, start.y, start.th, end.x, end.y, dt)
        for name, m, iv in zip(("forward", "leftward"), exact, np.asarray(mean), strict=True):
            if not _within(m, iv):
                self.fail(f"mean_velocity ({name}) interval {iv.tolist()} misses the exact odometry increment "
                          f"{mpmath.nstr(m, 17)}")  # fmt: skip

    def check_path(self, states: np.ndarray, taus: np.ndarray, record: Any = None) -> None:
        """Check each substep of a pymunk path in exact arithmetic: its yaw rate and body-frame velocity
        inside ``record`` (when given), the disc's clearance (when the checker has a ``radius``)."""
        for j in range(len(taus)):
            self.substeps += 1
            (x0, y0, a0), (x1, y1, a1) = states[j].tolist(), states[j + 1].tolist()
            tau = Fraction(float(taus[j]))
            if record is not None:
                rate = (Fraction(a1) - Fraction(a0)) / tau
                if not Fraction(float(record.yaw_rate[0])) <= rate <= Fraction(float(record.yaw_rate[1])):
                    self.fail(f"substep {j}: yaw-rate interval {record.yaw_rate.tolist()} misses the exact rate "
                              f"{float(rate)!r} (angle {a0!r} -> {a1!r} over {float(tau)!r} s)")  # fmt: skip
                ux, uy = (Fraction(x1) - Fraction(x0)) / tau, (Fraction(y1) - Fraction(y0)) / tau
                l1, h1, l2, h2 = velocity_extremes(ux, uy, a0, a1)
                for name, lo, hi in (("speed", l1, h1), ("lateral", l2, h2)):
                    iv = getattr(record, name)
                    if not (_within(lo, iv) and _within(hi, iv)):
                        self.fail(f"substep {j}: {name} interval {iv.tolist()} misses the exact body-frame "
                                  f"velocity in [{mpmath.nstr(lo, 17)}, {mpmath.nstr(hi, 17)}]")  # fmt: skip
            if self.radius is not None:
                self._check_clearance(j, (x0, y0), (x1, y1))

    def _check_clearance(self, j: int, p0: tuple[float, float], p1: tuple[float, float]) -> None:
        r = float(self.radius)  # type: ignore[arg-type]
        e = self.edges
        # float screen: the distance from the segment's points to an edge is at least the distance from p0
        # minus |p1 - p0|; edges farther than r + 0.01 that way cannot come within r (float error << 0.01)
        length = math.hypot(p1[0] - p0[0], p1[1] - p0[1])
        near = np.nonzero(_plain_dist(p0[0], p0[1], e) - length <= r + 0.01)[0]
        r2 = Fraction(r) ** 2
        for k in near:
            d2 = segment_distance2(p0, p1, e[k, :2], e[k, 2:])
            if d2 < r2:
                self.fail(f"substep {j}: the disc of radius {r} on the segment {p0} -> {p1} overlaps edge "
                          f"{e[k].tolist()} (distance {math.sqrt(float(d2))!r})")  # fmt: skip

    def _common(self, record: Any, truth: Any) -> None:
        p = np.asarray(truth.pose, dtype=np.float64)
        ex = self.pose
        assert ex is not None
        if p[2] != ex.th:
            self.fail(f"float heading {p[2]!r} is not the exact heading {ex.th!r}")
        err = float(getattr(truth, "pose_error", 0.0))
        with mpmath.workprec(PREC):
            ex_err = max(abs(mpmath.mpf(p[0]) - ex.x), abs(mpmath.mpf(p[1]) - ex.y))
            if not ex_err <= mpmath.mpf(err):
                self.fail(f"float position {p[:2].tolist()} is {mpmath.nstr(ex_err, 5)} m from the exact one, "
                          f"above pose_error {err!r}")  # fmt: skip
        if not _within(mpf(ex.th), record.heading):
            self.fail(f"heading interval {record.heading.tolist()} misses the exact heading {ex.th!r}")
        flags = np.asarray(record.outlier, dtype=bool)
        if self.max_outliers is not None and int(flags.sum()) > self.max_outliers:
            self.fail(f"{int(flags.sum())} outliers in one step, above the stated {self.max_outliers}")
        if not self.check_ranges:
            self.poses.append(ex.floats())
            self.exact_poses.append(ex)
            return
        rng = np.asarray(record.range, dtype=np.float64)
        r_max = np.asarray(record.r_max, dtype=np.float64)
        hi = np.where(np.isfinite(rng[:, 1]), rng[:, 1], 0.0)
        cap = np.maximum(r_max, hi) + 1.0
        d = cone_distances(
            ex, np.asarray(record.alpha), np.asarray(record.gamma), self.edges, cap, self.dense
        )
        self.poses.append(ex.floats())
        self.ranges.append(np.array([float(v) for v in d]))
        self.exact_poses.append(ex)
        self.exact_ranges.append(d)
        for s, ds in enumerate(d):
            if flags[s]:
                continue
            if record.no_echo[s]:
                if not ds > mpf(r_max[s]):
                    self.fail(f"sensor {s}: no echo claimed, but an obstacle lies at {mpmath.nstr(ds, 20)} "
                              f"<= r_max {r_max[s]!r}")  # fmt: skip
            if not _within(ds, rng[s]):
                self.fail(f"sensor {s}: range interval {rng[s].tolist()} misses the exact distance "
                          f"{mpmath.nstr(ds, 20)} (no_echo={bool(record.no_echo[s])})")  # fmt: skip


def check_episode(env: Any, seed: int, actions: Any, dense: bool = True, max_outliers: int | None = None,
                  radius: float | None = None, ranges: bool = True) -> PremiseChecker:  # fmt: skip
    """Reset ``env`` (raw or wrapped) with ``seed``, run ``actions`` (float64, so subnormal yaw actions
    survive) and check every step's record; returns the checker (its ``poses`` and ``ranges``)."""
    _, info = env.reset(seed=seed)
    chk = PremiseChecker(env.unwrapped.world.edges, dense=dense, max_outliers=max_outliers, radius=radius,
                         ranges=ranges)  # fmt: skip
    chk.reset(info["record"], info["truth"])
    for a in actions:
        _, _, term, trunc, info = env.step(np.asarray(a, dtype=np.float64))
        chk.step(info["record"], info["truth"])
        if term or trunc:
            break
    return chk
