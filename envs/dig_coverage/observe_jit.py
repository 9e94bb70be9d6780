"""The observation of one step, drawn in one compiled call: the map's channels and the ``"state"`` vector.

The layout is :mod:`digslam.envs.observation`'s (:class:`~digslam.envs.observation.Channel`,
:class:`~digslam.envs.observation.State`): :func:`observe_step` keeps the map's cell sets and its clear /
penumbra / dark channels up to date on the window of cells a step changed (the conservative downsampling of
:mod:`.maps_jit`), then draws the pose-box channel and writes every state entry. It is what
:class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver` calls once per step.

**The observation holds no ground truth.** The image and the state are drawn from the filter's sets, the
pose and heading boxes, the grid and the step count only. The ``reach`` plane (the true reachable free
cells) feeds nothing but the count these kernels return, which the wrapper puts in ``info`` and the reward;
the state's certified value is the share of the *grid's* cells that are clear, not of the reachable ones
(the grid is the observer's own, fixed by its configuration; the reachable area is what a real robot does
not know, and a share of it would tell the agent how much is left to find).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.envs.dig_coverage.maps_jit import (
    MapPlanes,
    PixelBlocks,
    fill_pixels,
    pixel_blocks,
    pixel_span,
    update_sets,
)
from digslam.envs.observation import Channel, State
from digslam.observer.core.grid_jit import window
from digslam.observer.core.scalar_jit import njit


class MapContext(NamedTuple):
    """What :func:`observe` reads and keeps between steps, built once per episode by :func:`map_context`
    (flat on purpose: each field, and each nested tuple more, costs at every call from Python).

    Attributes:
        sure, maybe, free: ``(ny, nx)`` bool, the filter's certainly and possibly sensed cells and ``M⁻``
            (read: the filter's own arrays).
        explored, clear, dark, reach: the map's cell sets, ``(ny, nx)`` uint8 planes (:class:`MapPlanes`),
            kept up to date on the cells a step changed.
        base: ``(3, m, m)`` uint8, the clear / penumbra / dark channels of the map (``Channel.CLEAR`` to
            ``Channel.DARK``), kept between steps.
        row_start, row_end, col_start, col_end: the pixel blocks (:class:`PixelBlocks`).
        xs, nys: the grid's exact cell bounds (``nys = -ys``), for the pose-box channel; the state is
            normalised over the grid's frame ``[xs[0], xs[-1]] × [-nys[-1], -nys[0]]``.
        horizon: the episode's step horizon (the state's elapsed-steps value is ``steps / horizon``).
    """

    sure: np.ndarray
    maybe: np.ndarray
    free: np.ndarray
    explored: np.ndarray
    clear: np.ndarray
    dark: np.ndarray
    reach: np.ndarray
    base: np.ndarray
    row_start: np.ndarray
    row_end: np.ndarray
    col_start: np.ndarray
    col_end: np.ndarray
    xs: np.ndarray
    nys: np.ndarray
    horizon: float


@njit
def observe(maps: MapContext, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
            win: tuple[int, int, int, int], steps: int, n_prev: int, img: np.ndarray, state: np.ndarray,
            snap: np.ndarray) -> int:  # fmt: skip
    """One step of the wrapper's observation in one compiled call: :func:`~.maps_jit.sets_and_map` of the
    window ``win`` of cells the step changed into the planes and ``base`` of ``maps`` (the clear / penumbra
    / dark channels), then those channels of ``img`` from ``base``, ``img[Channel.POSE]`` the pose-box
    footprint (the pixels whose blocks meet the cells of the position box ``pose_lo``, ``pose_hi``,
    :func:`~digslam.observer.core.grid_jit.window`) and every entry of ``state``
    (:class:`~digslam.envs.observation.State`, with the heading interval ``heading``; its
    ``State.CERTIFIED`` is the share of the grid's cells that are clear, from the observer alone);
    ``snap`` ``(3, ny, nx)`` uint8 receives copies of the explored codes, the clear mask and ``maps.free``
    (an empty ``snap``, ``(3, 0, 0)``: no copies).

    ``steps`` is the number of elapsed steps and ``n_prev`` the certified count before the step (clear cells
    in ``maps.reach``, ground truth); returns the new count, which enters neither ``img`` nor ``state``. No
    argument checks: the wrapper's own arrays (:class:`MapContext`, or the plain tuple of its fields).
    :func:`observe_step` is the same step with both counts kept by the caller (what the wrapper calls).
    """
    counts = np.array([n_prev, -1], np.int64)
    _observe(MapContext(*maps), pose_lo, pose_hi, heading, win, steps, counts, img, state, snap)
    return counts[0]


@njit
def observe_step(maps: tuple, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
                 win: tuple[int, int, int, int], steps: int, counts: np.ndarray, img: np.ndarray,
                 state: np.ndarray, snap: np.ndarray) -> None:  # fmt: skip
    """:func:`observe` with ``maps`` the plain tuple of the fields of a :class:`MapContext` (numba types a
    plain tuple argument in C, a named tuple field by field in Python: about 1.5 µs less per call) and
    ``counts`` ``(2,)`` int64, updated in place: the certified count (``observe``'s ``n_prev`` and result)
    and the number of clear cells of the grid (the state's certified share). Given that number before the
    step (``>= 0``), only the cells of ``win`` are counted again (the others did not change); ``-1``: all
    of them are counted. Same image, state and snapshot as :func:`observe`, to the bit."""
    _observe(MapContext(*maps), pose_lo, pose_hi, heading, win, steps, counts, img, state, snap)


@njit
def _count(c8: np.ndarray, win: tuple[int, int, int, int]) -> int:
    """The number of ones of the ``uint8`` 0 / 1 plane ``c8`` in the cells ``win = (r0, r1, c0, c1)``."""
    r0, r1, c0, c1 = win
    n = 0
    for i in range(r0, r1):
        row = c8[i, c0:c1]
        for j in range(row.size):
            n += np.int64(row[j])
    return n


@njit
def _observe(maps: MapContext, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
             win: tuple[int, int, int, int], steps: int, counts: np.ndarray, img: np.ndarray,
             state: np.ndarray, snap: np.ndarray) -> None:  # fmt: skip
    """The body of :func:`observe` and :func:`observe_step` (``counts`` as in :func:`observe_step`)."""
    sure, free = maps.sure, maps.free
    ny, nx = sure.shape
    planes = MapPlanes(maps.explored, maps.clear, maps.dark, maps.reach)
    blocks = PixelBlocks(maps.row_start, maps.row_end, maps.col_start, maps.col_end)
    base = maps.base
    r0, r1, c0, c1 = win
    p0, p1 = pixel_span(blocks.row_start, r0, r1, ny)
    q0, q1 = pixel_span(blocks.col_start, c0, c1, nx)
    c8, d8 = planes.clear.view(np.uint8), planes.dark.view(np.uint8)
    n_clear = counts[1]
    if n_clear >= 0:  # the clear cells outside the window are unchanged: count the window before and after
        n_clear -= _count(c8, win)
    counts[0] += update_sets(sure, maps.maybe, free, planes, win)
    if n_clear >= 0:
        n_clear += _count(c8, win)
    fill_pixels(c8, d8, base, 0, blocks, (p0, p1, q0, q1))
    e8, c8, s8 = planes.explored.view(np.uint8).reshape(-1), c8.reshape(-1), snap.reshape(-1)
    f8 = free.view(np.uint8).reshape(-1)
    k = e8.size
    s_e, s_c, s_f = s8[:k], s8[k : 2 * k], s8[2 * k :]  # the snapshot: explored, clear, free
    if n_clear < 0:  # every clear cell of the grid: the state's certified share (no ground truth)
        n_clear = 0
        for i in range(k):  # (slices indexed from 0: no wraparound checks, the loops vectorize)
            n_clear += np.int64(c8[i])
    counts[1] = n_clear
    if s8.size:  # the snapshot, when asked for (an empty ``snap``: none)
        for i in range(k):
            s_e[i] = e8[i]
        for i in range(k):
            s_c[i] = c8[i]
        for i in range(k):
            s_f[i] = f8[i]
    # flat loops (C-contiguous): they vectorize. ``base`` holds the channels CLEAR to DARK, in that order
    b8, flat = base.reshape(-1), img.reshape(-1)
    k = b8.size
    mm = k // 3  # pixels per channel
    o_b = flat[Channel.CLEAR * mm : Channel.CLEAR * mm + k]
    o_p = flat[Channel.POSE * mm : (Channel.POSE + 1) * mm]
    for i in range(k):
        o_b[i] = b8[i]
    for i in range(mm):
        o_p[i] = 0
    x0, y0, x1, y1 = pose_lo[0], pose_lo[1], pose_hi[0], pose_hi[1]
    f0, f1, g0, g1 = window(maps.xs, maps.nys, x0, y0, x1, y1)
    p0, p1 = pixel_span(blocks.row_start, f0, f1, ny)
    q0, q1 = pixel_span(blocks.col_start, g0, g1, nx)
    full = np.uint8(255)
    for p in range(p0, p1):
        row = img[Channel.POSE, p]
        for q in range(q0, q1):
            row[q] = full
    h0, h1 = heading
    xs, nys = maps.xs, maps.nys
    gx0, gx1, gy0, gy1 = xs[0], xs[xs.size - 1], -nys[nys.size - 1], -nys[0]  # the frame (exact)
    cx, cy, hx, hy = 0.5 * (gx0 + gx1), 0.5 * (gy0 + gy1), 0.5 * (gx1 - gx0), 0.5 * (gy1 - gy0)
    hm, hw = 0.5 * (h0 + h1), 0.5 * (h1 - h0)
    state[State.X_LO] = min(max((x0 - cx) / hx, -1.0), 1.0)
    state[State.Y_LO] = min(max((y0 - cy) / hy, -1.0), 1.0)
    state[State.X_HI] = min(max((x1 - cx) / hx, -1.0), 1.0)
    state[State.Y_HI] = min(max((y1 - cy) / hy, -1.0), 1.0)
    state[State.COS], state[State.SIN] = math.cos(hm), math.sin(hm)
    state[State.HEADING_WIDTH] = min(hw / math.pi, 1.0)
    state[State.TUBE] = math.tanh(max(x1 - x0, y1 - y0))
    state[State.ELAPSED] = min(steps / maps.horizon, 1.0)
    state[State.CERTIFIED] = n_clear / ny / nx
    state[State.CONSISTENT] = 1.0


def map_context(sets: tuple[np.ndarray, np.ndarray, np.ndarray], planes: MapPlanes, base: np.ndarray,
                xs: np.ndarray, nys: np.ndarray, horizon: float) -> MapContext:  # fmt: skip
    """The :class:`MapContext` of :func:`observe`: the filter's ``sets = (sure, maybe, free)``, the caller's
    ``planes`` and ``base`` (kept), the pixel blocks of ``base.shape[-1]`` pixels a side, the grid's cell
    bounds ``xs``, ``nys = -ys`` (its frame's ends first and last) and the ``horizon``."""
    blocks = pixel_blocks(planes.clear.shape, base.shape[-1])
    sure, maybe, free = sets
    return MapContext(sure, maybe, free, planes.explored, planes.clear, planes.dark, planes.reach, base,
                      blocks.row_start, blocks.row_end, blocks.col_start, blocks.col_end, xs, nys,
                      float(horizon))  # fmt: skip


__all__ = [
    "MapContext",
    "map_context",
    "observe",
    "observe_step",
]
