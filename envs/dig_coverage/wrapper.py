"""``GuaranteedObserver``: the online Dig-SLAM filter (thesis §6.4, Algorithm 6.3) wrapped around the raw env.

At every step the filter (:class:`~digslam.observer.online.observer.OnlineDigSlam`) turns the bounded record
into the
pose box, the dig zone ``M⁻`` and the explored thick set, and the wrapper hands them to the agent:

* ``"map"``: ``uint8 (C, m, m)`` channels-first image (SB3 image convention, values 0 / 255): clear,
  penumbra, dark (conservative downsampling, :mod:`.maps_jit`), the pose-box footprint, and with
  ``crop`` three more channels clear / penumbra / dark of a ``crop`` x ``crop`` m window centred on the pose
  box (world-aligned; outside the grid counts as dark);
* ``"state"``: ``float32 (N_STATE,)``: the pose box ``(x⁻, y⁻, x⁺, y⁺)`` normalised to ``[-1, 1]`` over the
  grid frame, ``cos``/``sin`` of the mid heading and the heading half-width over ``π``, ``tanh`` of the tube
  width (m), the elapsed share of ``horizon``, the certified share of the grid (clear cells over all the
  grid's cells: the clear area in m² over the grid's area) and the consistency flag.

The layout (each channel's and each state entry's index and meaning) is declared once in
:mod:`digslam.envs.observation` (:class:`~digslam.envs.observation.Channel`,
:class:`~digslam.envs.observation.State`); :func:`.observe_jit.observe_step` writes it.

**Observations from the observer only.** Everything in ``"map"`` and ``"state"`` comes from the filter's
sets and boxes, the grid and the step count: two worlds that give the same records (and the same start
box) give the same observations. Ground truth (the certifiable reachable free area, ``truth``) enters only
the reward, the termination and ``info``. So ``state[State.CERTIFIED]`` is *not*
``info["certified_coverage"]``: that one is a share of the certifiable reachable free area, which a real
robot does not know and which would tell the agent how much is left to find; the state's value grows with
the same clear area but over a denominator fixed in advance.

**Reward and termination: ground truth over the reachable free area.** The wrapper keeps the ground-truth
coverage of the reachable free area (:attr:`GuaranteedObserver.truth_coverage`, updated from
``info["truth"]``): the reward is the area it newly and truly sensed (m²), the episode terminates when all of
it is sensed (or when the env below terminates), and ``info["coverage"]`` is its share, equal to
``info["true_coverage"]``. (:class:`~digslam.envs.dig_coverage.env.DigCoverageEnv` rewards the certified area
instead.)

``info`` adds the pose box (``pose_box (2, 2)``, ``heading_box (2,)``), ``certified_coverage``
(clear cells in the certifiable reachable free area over that area, :func:`reachable_free`: closed cells
that meet no obstacle and connect to the start), ``clear_area`` (m²),
``true_coverage`` (the ground truth over the same cells: the share of the reachable free cells whose centre
was truly sensed, so ``certified_coverage <= true_coverage`` at every step, checked by ``monitor=True``)
and ``consistent`` / ``inconsistent_step``; with ``info_sets=True`` (:class:`.config.ObserverConfig`) also
copies of the sets (``explored`` int8 CLEAR/PENUMBRA/DARK, ``dig`` and ``clear`` bool, all ``(ny, nx)`` with
row 0 at the top), which :meth:`GuaranteedObserver.sets` gives on demand either way (off by default: three
full-grid copies a step are about a fifth of the observer's cost on a 256 x 256 grid, and only pictures
read them).
If the filter finds the data inconsistent (an empty pose box) it stops, every claim is withdrawn (the map
becomes all penumbra) and the episode is truncated.

**What is promised, and when the data break their bounds.** The claims (the true position lies in the pose
box and the heading in its interval; every dug or clear cell holds no obstacle point; every clear cell was
sensed, no dark cell was) are proved under a premise on the records; the filter never reads the record's
``outlier`` flag.

* ``q = 0`` (default): premise, *every* interval of every record contains the truth. If one range reading
  misses it, nothing is promised from that step on: the filter notices only when the data make the pose
  box empty, which may be steps later or never, and until then the reading's claims stand. One false long
  echo (or a range shifted up by 0.3 m) digs through a rock at once: obstacle cells claimed free and clear.
  Detection then withdraws every claim (and truncates the episode), but what the agent was shown before
  was false.
* ``q >= 1`` (``ObserverConfig(q=q)``, the filter's q-relaxed mode, thesis §2.6.2): premise, the
  odometry, compass and start box hold and *at most* ``q`` *of the range readings of each step* miss the
  truth (any readings, unflagged, possibly different ones each step). Then no claim is false, at any step:
  a cell is dug or clear only where ``q + 1`` readings of the step prove it free, the pose box is the hull of
  the positions consistent with all but ``q`` echoes, and the possibly sensed zone grows with the maximum
  ranges (:class:`~digslam.observer.online.observer.OnlineDigSlam`). This is the documented way to get no
  false
  claim from up to ``q`` bad readings per step; it costs coverage (fewer cells are proved) and some update
  time. With more than ``q`` bad readings in a step the ``q = 0`` statement applies again: an empty box is
  still reported, but claims made before may be false.

``digslam/DigCoverageOutliers-v0`` pairs the two: outliers capped at ``q = 1`` per step
(``noise.max_outliers``) and an observer with ``q = 1``.

Records go to the filter as they come: record ``k``'s odometry bounds the step that ends at ``t_k``, the
data contract of :mod:`digslam.observer.record.mission` that both the env and the filter follow.

>>> from digslam.envs.explore.env import ExploreEnv
>>> env = GuaranteedObserver(ExploreEnv(), map_size=36)
>>> obs, info = env.reset(seed=0)
>>> obs["map"].shape, obs["map"].dtype.name, obs["state"].shape, info["consistent"]
((4, 36, 36), 'uint8', (11,), True)
>>> bool(info["pose_box"][0, 0] <= info["truth"].pose[0] <= info["pose_box"][1, 0])
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from scipy import ndimage

from digslam.envs.dig_coverage.config import ObserverConfig
from digslam.envs.dig_coverage.maps_jit import MapPlanes, crop_window, fill_map
from digslam.envs.dig_coverage.monitor import GuaranteeMonitor
from digslam.envs.dig_coverage.observe_jit import map_context, observe_step
from digslam.envs.explore.coverage import Coverage
from digslam.envs.explore.env import ExploreEnv
from digslam.envs.observation import N_STATE, Channel, n_channels, observation_space
from digslam.envs.sim.raster import FREE, rasterize
from digslam.envs.sim.world import World
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.record.grid import Grid
from digslam.observer.thick.cells import PENUMBRA


def make_grid(cfg: ObserverConfig, world_frame: tuple[float, ...]) -> Grid:
    """The observer grid over ``cfg.grid_frame`` (default: the world frame); it must cover the world."""
    f = cfg.grid_frame or tuple(float(v) for v in world_frame)
    w = world_frame
    if not (f[0] <= w[0] and f[1] <= w[1] and f[2] >= w[2] and f[3] >= w[3]):
        raise ValueError(f"grid_frame: {f} does not cover the world frame {tuple(w)}")
    n = max(int(math.ceil((f[2] - f[0]) / cfg.grid_cell - 1e-9)), 1)
    return Grid((f[0], f[1]), (f[2], f[3]), (n, n))


def reachable_free(world: World, grid: Grid, start: np.ndarray, sub: int = 4) -> np.ndarray:
    """``(ny, nx)`` bool, row 0 at the top: the **certifiable reachable free area**, the denominator of the
    certified and the ground-truth coverage.

    A cell counts when its *closed* box meets no obstacle (``rasterize(..., closed=True)``: a cell that
    touches a wall only on its boundary, a wall along a cell edge or a vertex on a cell corner, is out) and
    it is connected to the start. The observer's claims are about closed cells, so a cell that touches an
    obstacle can never be proved free: counting it would keep certified coverage below 1 by construction.
    Both coverages count over these cells, so *certified <= ground truth <= 1* holds and 1 is reachable in
    principle.

    Connectivity is taken on a raster ``sub`` times finer (8-connected free fine cells), so passages
    narrower than an observer cell still connect the free space beyond them; a grid cell counts when its
    fine cells belong to the start's component.
    """
    x0, y0, x1, _ = grid.lo + grid.hi
    ny, nx = grid.shape
    res = (x1 - x0) / nx
    frame = (x0, y0, grid.hi[0], grid.hi[1])
    fine = rasterize(world.edges, frame, res / sub)[::-1] == FREE  # row 0 at the top
    fine = fine[: ny * sub, : nx * sub]
    labels, _ = ndimage.label(fine, structure=np.ones((3, 3), dtype=bool))
    col = int(Grid.count_below(grid.xs, np.array([start[0]]))[0]) - 1
    row = int(Grid.count_below(-grid.ys, np.array([-start[1]]))[0]) - 1
    r, c = min(max(row, 0), ny - 1) * sub, min(max(col, 0), nx - 1) * sub
    block = labels[r : r + sub, c : c + sub]
    lab = int(block.max())  # the start cell's component (its free fine cells are connected)
    if not lab:
        return np.zeros(grid.shape, dtype=bool)
    coarse = rasterize(world.edges, frame, res, closed=True)[::-1][:ny, :nx] == FREE
    inside = (labels == lab).reshape(ny, sub, nx, sub).all(axis=(1, 3))
    return coarse & inside


class GuaranteedObserver(gym.Wrapper):
    """The online guaranteed observer as a ``gymnasium`` wrapper (see the module docstring).

    Args:
        env: an :class:`~digslam.envs.explore.env.ExploreEnv` (possibly wrapped).
        grid_cell, map_size, crop, monitor, q: override the fields of ``config`` (``q`` also sets the
            filter's ``OnlineConfig.q``).
        config: an :class:`ObserverConfig`, a mapping, or an ``OnlineConfig`` (filter settings only).

    It reads the env below through its public API and ``info`` only: ``env.unwrapped``'s ``generator``,
    ``world`` and ``suite``, the record and the ground truth of each step's ``info``. When ``env`` is an
    :class:`~digslam.envs.explore.env.ExploreEnv` itself (no wrapper between), :meth:`step` calls its
    :meth:`~digslam.envs.explore.env.ExploreEnv.step_record`: the agent sees this wrapper's observation only,
    so the raw one is not built on each step.
    """

    n_reachable: int
    _clear_count: int

    def __init__(
        self,
        env: gym.Env,
        grid_cell: float | None = None,
        map_size: int | None = None,
        crop: float | None = None,
        monitor: bool | None = None,
        config: ObserverConfig | OnlineConfig | Mapping[str, Any] | None = None,
        q: int | None = None,
    ) -> None:
        super().__init__(env)
        if isinstance(config, OnlineConfig):
            config = ObserverConfig(online=config)
        cfg = config if isinstance(config, ObserverConfig) else ObserverConfig.from_dict(config or {})
        over = {"grid_cell": grid_cell, "map_size": map_size, "crop": crop, "monitor": monitor}
        cfg = cfg.replace(**{k: v for k, v in over.items() if v is not None})
        if q is not None:
            if not (isinstance(q, int) and not isinstance(q, bool) and q >= 0):
                raise ValueError(f"q: must be an integer >= 0 (outliers allowed per step), got {q!r}")
            cfg = cfg.replace(q=q, online=cfg.online.replace(q=q))
        self.obs_config = cfg
        raw = env.unwrapped
        if not isinstance(raw, ExploreEnv):
            raise TypeError(f"env: must be an ExploreEnv, possibly wrapped; got {type(raw).__name__} below")
        self._explore = raw  # the raw env at the bottom (read through its public attributes only)
        self.grid = make_grid(cfg, raw.generator.frame)
        m = cfg.map_size
        self.n_channels = n_channels(cfg.crop is not None)
        self.observation_space = observation_space(m, cfg.crop is not None)
        self.filter = OnlineDigSlam(self.grid, cfg.online)
        # nothing between reads the raw observation, which this wrapper replaces: skip building it
        self._direct: ExploreEnv | None = env if isinstance(env, ExploreEnv) else None
        self._extra_info: dict[str, Any] = {}  # constant keys added to every info (subclasses)
        g = self.grid
        self.cell_area = g.cell_size[0] * g.cell_size[1]
        self._obs: tuple[np.ndarray, np.ndarray] = (np.zeros(0, np.uint8), np.zeros(0, np.float32))
        self._reach_world: World | None = None
        self.reachable = np.zeros(g.shape, dtype=bool)
        self.monitor: GuaranteeMonitor | None = None
        self.n_reachable = 1  # the reachable free cells (at least 1: a denominator)
        self._clear_count = 0  # the certified count at the last reward (DigCoverageEnv)
        self._suite = raw.suite
        self.steps, self._cache_step = 0, -1
        self._cache: tuple[np.ndarray, np.ndarray, np.ndarray, int] = (np.zeros(0),) * 3 + (0,)
        self._dig_copy = np.zeros(0, bool)
        m, shape = cfg.map_size, g.shape
        # explored (int8), clear, dark, reachable (ground truth: only for the count of info and the reward)
        self._planes = np.zeros((4, *shape), np.uint8)
        self._explored_all, self._clear_all = self._planes[0].view(np.int8), self._planes[1].view(np.bool_)
        self._dark_all, self._base, self._n = self._planes[2].view(np.bool_), np.zeros((3, m, m), np.uint8), 0
        self._xs, self._nys = np.array(g.xs, np.float64), np.array(-g.ys, np.float64)
        # what :func:`.observe_jit.observe_step` reads and keeps (each reset), as the plain tuple of its
        # fields
        self._maps: tuple = ()
        # the certified count and the grid's number of clear cells, kept by :func:`.observe_jit.observe_step`
        self._counts = np.zeros(2, np.int64)
        self._img_shape, self._snap_shape = (self.n_channels, m, m), (3, *shape)

    # --- gymnasium API -------------------------------------------------------------------------------------
    def reset(self, **kwargs: Any) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        _, info = self.env.reset(**kwargs)
        raw, world = self._explore, self._world()
        truth = info["truth"]
        self._suite = raw.suite
        self.grid_check(world)
        if self._reach_world is not world or not self._in_reach(truth.pose):  # once per world and start
            self.reachable = reachable_free(world, self.grid, truth.pose)
            self.n_reachable = max(int(np.count_nonzero(self.reachable)), 1)
            self._planes[3] = self.reachable
            self._reach_world = world
        b = self.obs_config.start_box
        p = truth.pose[:2]
        lo = np.maximum(p - b, np.array(self.grid.lo))
        hi = np.minimum(p + b, np.array(self.grid.hi))
        self.filter.reset(lo, hi, info["record"])
        f = self.filter
        sets = (f.sensed_sure, f.sensed_maybe, f.dig.free)
        self._maps = tuple(map_context(sets, MapPlanes(*self._planes), self._base, self._xs, self._nys,
                                       self.obs_config.horizon))  # fmt: skip
        self.steps, self._cache_step = 0, -1
        # ground truth over the cells of the certified coverage, the reachable free area
        # (:mod:`digslam.envs.explore.coverage`)
        self.truth_coverage = Coverage.on_cells(self.reachable[::-1], self.grid.lo, self.grid.cell_size,
                                                float(raw.suite.r_max.max()))  # fmt: skip
        self.truth_coverage.update(truth.pose, raw.suite, truth.ranges)
        self.monitor = (GuaranteeMonitor(world, self.grid, coverage=(self.reachable, self.truth_coverage))
                        if self.obs_config.monitor else None)  # fmt: skip
        self._check(info)
        self._clear_count = self._certified_count()
        return self.observation(), self._obs_info(info)

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if self._direct is not None:
            _, terminated, truncated, info = self._direct.step_record(action)
        else:
            _, _, terminated, truncated, info = self.env.step(action)
        truth = info["truth"]
        reward = self.truth_coverage.update(truth.pose, self._suite, truth.ranges)
        terminated = terminated or self.truth_coverage.fraction >= 1.0
        self.filter.update(info["record"])
        self.steps += 1
        if self.monitor is not None:
            self.monitor.check(self.filter, info["truth"], info["record"], self.steps)
        truncated = truncated or not self.filter.consistent
        return self.observation(), float(reward), terminated, truncated, self._obs_info(info)

    def _world(self) -> World:
        """The raw env's current world (ground truth; set by ``reset``)."""
        if self._explore.world is None:
            raise RuntimeError("call reset() first")
        return self._explore.world

    # --- pieces ---------------------------------------------------------------------------------------------
    def _in_reach(self, pose: np.ndarray) -> bool:
        g = self.grid
        c = int(Grid.count_below(g.xs, np.array([pose[0]]))[0]) - 1
        r = int(Grid.count_below(-g.ys, np.array([-pose[1]]))[0]) - 1
        return 0 <= r < g.shape[0] and 0 <= c < g.shape[1] and bool(self.reachable[r, c])

    def grid_check(self, world: World) -> None:
        """Raise ``ValueError`` if the grid does not cover ``world``'s frame."""
        make_grid(self.obs_config.replace(grid_frame=self.grid.lo + self.grid.hi), world.frame)

    def _check(self, info: dict[str, Any]) -> None:
        if self.monitor is not None:
            self.monitor.check(self.filter, info["truth"], info["record"], self.steps)

    def _sets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """The filter's explored codes, clear and dark masks and certified cell count, once per step, with
        the observation (:meth:`observation`): one compiled call (:func:`.observe_jit.observe_step`)
        keeps the sets and the map's clear / penumbra / dark channels up to
        date on the cells the step touched (:meth:`OnlineDigSlam.take_touched`) and draws the pose-box channel
        and the state. Returns info's copies of the explored codes and the clear mask (empty ``(0, 0)`` arrays
        without ``info_sets``: not copied), the kept dark mask and the certified count."""
        if self._cache_step != self.steps:
            f, counts = self.filter, self._counts
            win = f.take_touched()
            if win == (0, self._snap_shape[1], 0, self._snap_shape[2]):  # after a reset: everything (and the
                self._clear_all[:] = False  # reachable area may be new): both counts from scratch
                counts[0], counts[1] = 0, -1
            img, state = np.empty(self._img_shape, np.uint8), np.empty(N_STATE, dtype=np.float32)
            # info's explored, clear and dig (info_sets), or nothing (the kernel then copies nothing)
            snap = np.empty(self._snap_shape if self.obs_config.info_sets else (3, 0, 0), np.uint8)
            observe_step(self._maps, f.pose_lo, f.pose_hi, (f.heading_lo, f.heading_hi), win, self.steps,
                         counts, img, state, snap)  # fmt: skip
            self._n = n = int(counts[0])
            if self.obs_config.crop is not None:
                self._crop(img)
            self._obs = (img, state)
            self._cache = (snap[0].view(np.int8), snap[1].view(np.bool_), self._dark_all, n)
            self._dig_copy = snap[2].view(np.bool_)  # (empty without info_sets: never read then)
            self._cache_step = self.steps
        return self._cache

    def _crop(self, img: np.ndarray) -> None:
        """Channels ``Channel.CROP_CLEAR`` to ``Channel.CROP_DARK``: clear / penumbra / dark of the ``crop``
        window centred on the pose box."""
        f, g = self.filter, self.grid
        assert self.obs_config.crop is not None  # (called with a crop window only)
        k = max(int(math.ceil(self.obs_config.crop / g.cell_size[0])), 1)
        ctr = 0.5 * (f.pose_lo + f.pose_hi)
        rc = int(Grid.count_below(-g.ys, np.array([-ctr[1]]))[0]) - 1
        cc = int(Grid.count_below(g.xs, np.array([ctr[0]]))[0]) - 1
        a, b = rc - k // 2, cc - k // 2
        clear, dark = crop_window(self._clear_all, a, b, k, False), crop_window(self._dark_all, a, b, k, True)
        fill_map(clear, dark, img, Channel.CROP_CLEAR)

    def _certified_count(self) -> int:
        """Clear cells in the reachable free area (0 once the claims are withdrawn)."""
        return self._sets()[3] if self.filter.consistent else 0

    def observation(self) -> dict[str, np.ndarray]:
        """The ``"map"`` and ``"state"`` of the filter's current sets (serves reset and step)."""
        if not self.filter.consistent:  # claims withdrawn: everything is penumbra
            m = self.obs_config.map_size
            img = np.zeros((self.n_channels, m, m), dtype=np.uint8)
            img[Channel.PENUMBRA] = 255
            return {"map": img, "state": np.zeros(N_STATE, dtype=np.float32)}
        self._sets()
        img, state = self._obs
        return {"map": img, "state": state}

    def sets(self) -> dict[str, np.ndarray]:
        """Copies of the observer's sets now: ``explored`` (int8 CLEAR / PENUMBRA / DARK), ``dig`` (``M⁻``)
        and ``clear`` (bool), ``(ny, nx)`` with row 0 at the top; what ``info`` carries with
        ``info_sets=True`` (once the claims are withdrawn: all penumbra, nothing dug or clear)."""
        f = self.filter
        if not f.consistent:
            shape = self.grid.shape
            return {"explored": np.full(shape, PENUMBRA, np.int8), "dig": np.zeros(shape, bool),
                    "clear": np.zeros(shape, bool)}  # fmt: skip
        self._sets()  # the planes up to date with this step
        explored, clear = self._explored_all.copy(), self._clear_all.copy()
        return {"explored": explored, "dig": f.dig.free.copy(), "clear": clear}

    def _obs_info(self, info: dict[str, Any]) -> dict[str, Any]:
        f, t = self.filter, self.truth_coverage.fraction
        if f.consistent:
            explored, clear, _, n = self._sets()
            if self.obs_config.info_sets:
                info = {**info, "explored": explored, "dig": self._dig_copy, "clear": clear}
            return {**info,
                    "pose_box": np.array((f.pose_lo, f.pose_hi), np.float64),
                    "heading_box": np.array((f.heading_lo, f.heading_hi), np.float64),
                    "certified_coverage": n / self.n_reachable, "clear_area": n * self.cell_area,
                    "true_coverage": t, "coverage": t, "consistent": True,
                    "inconsistent_step": f.inconsistent_step, **self._extra_info}  # fmt: skip
        if self.obs_config.info_sets:
            info = {**info, **self.sets()}
        return {**info, "pose_box": np.full((2, 2), np.nan),
                "heading_box": np.full(2, np.nan), "certified_coverage": 0 / self.n_reachable,
                "clear_area": 0 * self.cell_area, "true_coverage": t, "coverage": t,
                "consistent": False, "inconsistent_step": f.inconsistent_step,
                **self._extra_info}  # fmt: skip


__all__ = [
    "GuaranteedObserver",
    "make_grid",
    "reachable_free",
]
