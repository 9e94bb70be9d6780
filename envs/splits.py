"""Seed splits of the environments: train, validation and test levels (Procgen / MiniGrid style).

Every registered environment builds a new world and a new start pose from the seed passed to ``reset``
(:class:`~digslam.envs.config.ExploreConfig`: ``fixed_world=False``, ``room_jitter``, ``start_rule``), so a
seed *is* a level. The levels are split once and for all:

* :data:`TRAIN`: seeds ``0 .. 999 999``, for training (an unseeded reset draws the next world from the
  episode's random stream, which stays clear of the other splits' worlds but for a 2⁻³¹ chance per world);
* :data:`VALIDATION`: seeds ``1 000 000 .. 1 000 999``, for evaluation during training and for tuning the
  heuristics' knobs;
* :data:`TEST`: seeds ``2 000 000 .. 2 000 999``, for the benchmark only. The training script refuses them
  (:func:`check_not_test`), so a leaderboard figure is never measured on a level an agent was tuned on.

>>> split_of(5), split_of(1_000_003), split_of(2_000_000), split_of(3_000_000)
('train', 'validation', 'test', None)
>>> seeds("test", 3)
[2000000, 2000001, 2000002]

**Real buildings: split by plan.** On ``world="floorplan"`` with the shipped plans, a level is a window of
one of ten KTH floor plans, and the split of the reset's seed also chooses the *plans* its window is cut
from (:data:`digslam.envs.sim.generators.floorplan.SPLIT`; an unseeded reset counts as ``train``): six
plans train, two validate, two test. Windows of one plan overlap and floors of one building look alike, so
a split of the seeds alone would show a test level's walls in training; split by plan, no window of a test
level comes from a plan that training or validation uses. Which plan goes where, and why, is
:data:`~digslam.envs.sim.generators.floorplan.SPLIT`'s comment. A seed outside every split draws from all
ten plans, and with the user's maps (``floorplans=[...]``) every seed is a level of any map: no split
applies.

>>> from digslam.envs.sim.generators.floorplan import SPLIT
>>> {split: len(plans) for split, plans in SPLIT.items()}
{'train': 6, 'validation': 2, 'test': 2}
"""

from __future__ import annotations

from collections.abc import Iterable

TRAIN = range(0, 1_000_000)
VALIDATION = range(1_000_000, 1_001_000)
TEST = range(2_000_000, 2_001_000)
#: Split name to its seeds.
SPLITS = {"train": TRAIN, "validation": VALIDATION, "test": TEST}


def split_of(seed: int) -> str | None:
    """The split holding ``seed`` (None for a seed outside every split)."""
    for name, r in SPLITS.items():
        if seed in r:
            return name
    return None


def seeds(split: str, n: int, offset: int = 0) -> list[int]:
    """The ``n`` seeds of ``split`` from its ``offset``-th on; ValueError naming the split or ``n``."""
    if split not in SPLITS:
        raise ValueError(f"split: must be one of {sorted(SPLITS)}, got {split!r}")
    r = SPLITS[split]
    ok = isinstance(n, int) and isinstance(offset, int) and 0 <= n and 0 <= offset and offset + n <= len(r)
    if not ok:
        raise ValueError(f"n: {n} seeds from offset {offset} do not fit split {split!r} ({len(r)} seeds)")
    return list(r[offset : offset + n])


def check_not_test(name: str, values: Iterable[int]) -> None:
    """ValueError naming ``name`` when a seed of ``values`` belongs to the test split: training and tuning
    never see the benchmark's levels."""
    bad = sorted(s for s in values if s in TEST)
    if bad:
        raise ValueError(
            f"{name}: seeds {bad[:3]}{'...' if len(bad) > 3 else ''} belong to the test split "
            f"({TEST.start}..{TEST.stop - 1}), which training and tuning must not use; pick train seeds "
            f"(0..{TRAIN.stop - 1}) or validation seeds ({VALIDATION.start}..{VALIDATION.stop - 1})"
        )


__all__ = [
    "SPLITS",
    "TEST",
    "TRAIN",
    "VALIDATION",
    "check_not_test",
    "seeds",
    "split_of",
]
