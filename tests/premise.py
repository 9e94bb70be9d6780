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

Use :class:`PremiseChecker` (``reset`` then ``step`` with each ``(record, truth)``), or :func:`check_episode`
to drive an env through actions; both raise :class:`PremiseViolation` naming the step and the quantity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
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
    """

    def __init__(self, edges: np.ndarray, dense: bool = True, max_outliers: int | None = None) -> None:
        self.edges = np.ascontiguousarray(edges, dtype=np.float64).reshape(-1, 4)
        self.dense, self.max_outliers = dense, max_outliers
        self.pose: ExactPose | None = None
        self.t = 0.0
        self.k = 0
        #: Per step: the exact pose (floats) and the exact ranges (floats; inf where none within the cap).
        self.poses: list[np.ndarray] = []
        self.ranges: list[np.ndarray] = []
        #: The same exactly: :class:`ExactPose` and mp distances.
        self.exact_poses: list[ExactPose] = []
        self.exact_ranges: list[list[Any]] = []
        #: The pieces of each step after reset.
        self.pieces: list[np.ndarray] = []

    def fail(self, msg: str) -> None:
        raise PremiseViolation(f"step {self.k}: {msg}")

    def reset(self, record: Any, truth: Any) -> ExactPose:
        """Record 0: the reset pose is exact; the robot is at rest."""
        self.k = 0
        p = np.asarray(truth.pose, dtype=np.float64)
        self.pose = ExactPose(mpf(p[0]), mpf(p[1]), float(p[2]))
        seg = pieces(truth)
        if seg.shape != (2, 3):
            self.fail(f"pieces: expected shape (2, 3), got {seg.shape}")
        if np.any(seg[:, :2] != 0) or np.any(seg[:, 2] != p[2]):
            self.fail(f"reset: pieces {seg.tolist()} should be at rest, at the start heading {p[2]!r}")
        self.t = float(record.t)
        self.poses, self.ranges, self.exact_poses, self.exact_ranges, self.pieces = [], [], [], [], []
        for name in ("speed", "yaw_rate"):
            if not _within(mpf(0.0), getattr(record, name)):
                self.fail(f"{name} interval {getattr(record, name).tolist()} misses 0 (robot at rest)")
        self._common(record, truth)
        return self.pose

    def step(self, record: Any, truth: Any) -> ExactPose:
        """One step: advance the exact pose along ``truth.pieces`` and check ``record``."""
        assert self.pose is not None, "reset first"
        self.k += 1
        seg = pieces(truth)
        if seg.shape != (2, 3) or not np.all(np.isfinite(seg)):
            self.fail(f"pieces: expected finite (2, 3), got {seg!r}")
        self.pieces.append(seg)
        t = float(record.t)
        if float(truth.t) != t:
            self.fail(f"truth.t {float(truth.t)!r} != record.t {t!r}")
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
        self.pose = ExactPose(x, y, th)
        self.t = t
        self._common(record, truth)
        return self.pose

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


def check_episode(env: Any, seed: int, actions: Any, dense: bool = True,
                  max_outliers: int | None = None) -> PremiseChecker:  # fmt: skip
    """Reset ``env`` (raw or wrapped) with ``seed``, run ``actions`` (float64, so subnormal yaw actions
    survive) and check every step's record; returns the checker (its ``poses`` and ``ranges``)."""
    _, info = env.reset(seed=seed)
    chk = PremiseChecker(env.unwrapped.world.edges, dense=dense, max_outliers=max_outliers)
    chk.reset(info["record"], info["truth"])
    for a in actions:
        _, _, term, trunc, info = env.step(np.asarray(a, dtype=np.float64))
        chk.step(info["record"], info["truth"])
        if term or trunc:
            break
    return chk
