"""Frozen, validated configuration of the observer wrapper and of the certified-coverage environments.

Like :mod:`digslam.envs.config`, every config is a frozen dataclass on the project's config base
(:mod:`digslam.observer.core.config`): its constructor and :meth:`from_dict` reject unknown keys with a
``ValueError`` naming them, and its values are checked with the offending field named.

>>> ObserverConfig(map_size=48).map_size
48
>>> ObserverConfig(map_size=20)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: map_size: 20 is below 36, the smallest image SB3's NatureCNN accepts; declare ...
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field
from typing import Any

from digslam.envs.config import ExploreConfig
from digslam.observer.core.config import (
    Config,
    check,
    check_finite_nonneg,
    check_in,
    check_int,
    config_dataclass,
)
from digslam.observer.online.observer import OnlineConfig

#: Smallest image side SB3's ``NatureCNN`` accepts (three valid convolutions of 8/4, 4/2 and 3/1).
NATURE_CNN_MIN = 36


@config_dataclass
class ObserverConfig(Config):
    """Settings of :class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver`.

    Attributes:
        grid_cell: Side of the observer's grid cells (m); the grid has ``ceil(span / grid_cell)`` cells
            per side (128 x 128 over the default 20 m room).
        grid_frame: ``(xmin, ymin, xmax, ymax)`` of the (square) observer grid; None = the world's frame.
            It must cover the world's frame.
        map_size: Side of the ``"map"`` image (pixels); at least 36 unless ``custom_extractor``.
        crop: Side (m) of the egocentric crop added as three more channels; None = no crop.
        custom_extractor: Declare that the policy uses a custom features extractor (lifts the 36 px floor).
        monitor: Check every step's claims against the privileged ground truth (debug; see
            :mod:`.monitor`).
        start_box: Half-width (m) of the initial position box around the true start.
        info_sets: Put copies of the observer's sets (``explored``, ``clear``, ``dig``: full grids) in every
            step's ``info``. Off by default: the three copies are about a fifth of the observer's cost on a
            256 x 256 grid and nothing in training or evaluation reads them; the wrapper's ``sets()`` gives
            the same copies on demand (the pictures read them there).
        horizon: Steps that normalise the elapsed time in ``"state"`` (the registered step limit).
        online: Settings of the online filter (an ``OnlineConfig`` or a mapping).
        q: Outliers allowed among the range readings of one step: the filter's q-relaxed mode
            (``OnlineConfig.q``, thesis §2.6.2), the way to make no false claim from up to ``q`` bad readings
            per step. 0 keeps ``online.q``; a non-zero value sets it (and must agree with a non-zero
            ``online.q``). After construction ``q == online.q``.
    """

    grid_cell: float = 0.15625
    grid_frame: tuple[float, float, float, float] | None = None
    map_size: int = 64
    crop: float | None = None
    custom_extractor: bool = False
    monitor: bool = False
    start_box: float = 0.0
    info_sets: bool = False
    horizon: int = 1000
    online: OnlineConfig = field(default_factory=OnlineConfig)
    q: int = 0

    def __post_init__(self) -> None:
        if isinstance(self.online, Mapping):
            object.__setattr__(self, "online", OnlineConfig.from_dict(self.online))
        check(isinstance(self.online, OnlineConfig), "online", "must be an OnlineConfig or a mapping")
        q = self.q
        check_int("q", q, 0, " (outliers allowed per step)")
        check(
            not (q and self.online.q and q != self.online.q),
            "q",
            f"{q} disagrees with online.q = {self.online.q}",
        )
        if q and not self.online.q:
            object.__setattr__(self, "online", self.online.replace(q=q))
        object.__setattr__(self, "q", self.online.q)
        c = self.grid_cell
        check(
            isinstance(c, (int, float)) and math.isfinite(c) and c > 0,
            "grid_cell",
            f"cell size must be finite and > 0, got {c!r}",
        )
        m = self.map_size
        check(isinstance(m, int) and m >= 1, "map_size", f"must be a positive integer, got {m!r}")
        check(
            m >= NATURE_CNN_MIN or self.custom_extractor,
            "map_size",
            f"{m} is below {NATURE_CNN_MIN}, the smallest image SB3's NatureCNN accepts; declare "
            "custom_extractor=True to use a custom features extractor",
        )
        if self.crop is not None:
            check(
                isinstance(self.crop, (int, float)) and math.isfinite(self.crop) and self.crop > 0,
                "crop",
                f"must be None or a crop side > 0 (m), got {self.crop!r}",
            )
        if self.grid_frame is not None:
            f = tuple(float(v) for v in self.grid_frame)
            check(
                len(f) == 4 and all(math.isfinite(v) for v in f) and f[0] < f[2] and f[1] < f[3],
                "grid_frame",
                f"must be a finite (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax, got {f}",
            )
            check(
                math.isclose(f[2] - f[0], f[3] - f[1], rel_tol=1e-9),
                "grid_frame",
                f"must be square (square cells), got {f}",
            )
            object.__setattr__(self, "grid_frame", f)
        check_finite_nonneg("start_box", self.start_box)
        check(isinstance(self.info_sets, bool), "info_sets", f"must be a bool, got {self.info_sets!r}")
        check(isinstance(self.horizon, int) and self.horizon >= 1, "horizon", f"invalid {self.horizon!r}")


@config_dataclass
class DigCoverageConfig(Config):
    """Settings of ``digslam/DigCoverage-v0`` (the reward and termination; the rest lives in ``observer``
    and ``explore``).

    Attributes:
        target: Terminate when certified coverage reaches this share of the reachable free area.
        collision_penalty: Reward subtracted per bump (new wall contact).
        observer: An :class:`ObserverConfig` or a mapping.
        explore: An :class:`~digslam.envs.config.ExploreConfig` or a mapping (the raw env).
    """

    target: float = 0.8
    collision_penalty: float = 1.0
    observer: ObserverConfig = field(default_factory=ObserverConfig)
    explore: ExploreConfig = field(default_factory=ExploreConfig)

    def __post_init__(self) -> None:
        if isinstance(self.observer, Mapping):
            object.__setattr__(self, "observer", ObserverConfig.from_dict(self.observer))
        if isinstance(self.explore, Mapping):
            object.__setattr__(self, "explore", ExploreConfig.from_dict(self.explore))
        check(isinstance(self.observer, ObserverConfig), "observer", "must be an ObserverConfig or a mapping")
        check(isinstance(self.explore, ExploreConfig), "explore", "must be an ExploreConfig or a mapping")
        check_in("target", self.target, 0.0, 1.0, lo_open=True)
        check_finite_nonneg("collision_penalty", self.collision_penalty)

    @classmethod
    def split(cls, kwargs: Mapping[str, Any]) -> DigCoverageConfig:
        """Route flat keyword arguments: coverage keys here, observer keys to ``observer``, the others to
        ``explore`` (whose unknown keys raise ``ValueError``)."""
        own = {f for f in cls.__dataclass_fields__}
        obs = set(ObserverConfig.__dataclass_fields__)
        raw = set(ExploreConfig.__dataclass_fields__)
        unknown = sorted(set(kwargs) - own - obs - raw)
        if unknown:  # name every key the user can pass here, not only the raw env's
            import difflib

            known = sorted((own - {"observer", "explore"}) | obs | raw)
            hints = [m for k in unknown for m in difflib.get_close_matches(k, known, n=1)]
            hint = f" (did you mean {', '.join(map(repr, hints))}?)" if hints else ""
            coverage_keys = sorted(own - {"observer", "explore"})
            raise ValueError(
                f"DigCoverage: unknown keyword(s) {unknown}{hint}; known: coverage {coverage_keys}, observer "
                f"{sorted(obs)}, raw environment {sorted(raw)}"
            )
        mine = {k: v for k, v in kwargs.items() if k in own}
        o = {k: v for k, v in kwargs.items() if k in obs}
        e = {k: v for k, v in kwargs.items() if k not in own and k not in obs}
        base_o = mine.pop("observer", {})
        base_e = mine.pop("explore", {})
        if isinstance(base_o, ObserverConfig):
            observer = base_o.replace(**o)
        else:
            observer = ObserverConfig.from_dict(base_o, **o)
        if isinstance(base_e, ExploreConfig):
            explore = base_e.replace(**e)
        else:
            explore = ExploreConfig.from_dict(base_e, **e)
        return cls(observer=observer, explore=explore, **mine)


__all__ = [
    "DigCoverageConfig",
    "NATURE_CNN_MIN",
    "ObserverConfig",
]
