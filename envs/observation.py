"""The observation of the certified-coverage environments, declared once: its channels and its state.

Every ``digslam/DigCoverage-*`` env (:class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver`)
returns ``{"map": uint8 (C, m, m), "state": float32 (N_STATE,)}``. This module is the one place that says
what each channel and each state entry means: the observation space (:func:`observation_space`), the
compiled writer (:mod:`digslam.envs.dig_coverage.observe_jit`), the agents' parsers and the docs' table
(:func:`markdown_table`) all read it.

``"map"`` is a channels-first image (SB3's image convention, values 0 or 255) over the grid's frame, row 0
at the largest ``y``. A pixel stands for a block of grid cells and never upgrades a claim: it is CLEAR only
if every cell of its block is clear, DARK only if every cell is dark (:data:`Channel`). ``"state"`` entries
lie in ``[-1, 1]`` (:data:`State`).

Nothing in an observation is ground truth: both parts come from the observer's sets and boxes, the grid and
the step count.

>>> int(Channel.DARK), int(State.CONSISTENT), N_STATE, n_channels(crop=True)
(2, 10, 11, 7)
"""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # gymnasium is imported by observation_space only
    from gymnasium import spaces


class Channel(IntEnum):
    """Channels of ``obs["map"]``; the three ``CROP_*`` exist only with ``crop`` set (a window of ``crop``
    metres a side centred on the pose box, world-aligned; outside the grid counts as dark)."""

    CLEAR = 0
    PENUMBRA = 1
    DARK = 2
    POSE = 3
    CROP_CLEAR = 4
    CROP_PENUMBRA = 5
    CROP_DARK = 6


class State(IntEnum):
    """Entries of ``obs["state"]``."""

    X_LO = 0
    Y_LO = 1
    X_HI = 2
    Y_HI = 3
    COS = 4
    SIN = 5
    HEADING_WIDTH = 6
    TUBE = 7
    ELAPSED = 8
    CERTIFIED = 9
    CONSISTENT = 10


#: What each channel holds.
CHANNELS: dict[Channel, str] = {
    Channel.CLEAR: "clear: every cell of the pixel's block is proved free and certainly sensed",
    Channel.PENUMBRA: "penumbra: neither clear nor dark (mixed, or possibly sensed)",
    Channel.DARK: "dark: every cell of the pixel's block is certainly never sensed",
    Channel.POSE: "the pose box's footprint",
    Channel.CROP_CLEAR: "with ``crop``: clear, on the window centred on the pose box",
    Channel.CROP_PENUMBRA: "with ``crop``: penumbra, on that window",
    Channel.CROP_DARK: "with ``crop``: dark, on that window (outside the grid counts as dark)",
}

#: What each state entry holds (every entry lies in ``[-1, 1]``).
STATES: dict[State, str] = {
    State.X_LO: "pose box ``x⁻``, normalised to ``[-1, 1]`` over the grid's frame",
    State.Y_LO: "pose box ``y⁻``, likewise",
    State.X_HI: "pose box ``x⁺``, likewise",
    State.Y_HI: "pose box ``y⁺``, likewise",
    State.COS: "``cos`` of the heading interval's midpoint",
    State.SIN: "``sin`` of the heading interval's midpoint",
    State.HEADING_WIDTH: "the heading interval's half-width over ``π`` (at most 1)",
    State.TUBE: "``tanh`` of the pose box's larger side (m)",
    State.ELAPSED: "the elapsed share of the horizon (at most 1)",
    State.CERTIFIED: "clear cells over all the grid's cells (a fixed denominator, not the reachable area)",
    State.CONSISTENT: "1 while the observer's data are consistent, else 0 (every claim then withdrawn)",
}

#: Length of ``obs["state"]``.
N_STATE = len(State)
#: Channels without and with ``crop``.
BASE_CHANNELS, CROP_CHANNELS = int(Channel.POSE) + 1, len(Channel)


def n_channels(crop: bool) -> int:
    """Number of ``"map"`` channels: 4, or 7 with a ``crop`` window."""
    return CROP_CHANNELS if crop else BASE_CHANNELS


def observation_space(map_size: int, crop: bool) -> spaces.Dict:
    """The ``Dict`` space of an observation with a ``map_size`` pixel map (needs gymnasium)."""
    import numpy as np
    from gymnasium import spaces

    return spaces.Dict(
        {
            "map": spaces.Box(0, 255, shape=(n_channels(crop), map_size, map_size), dtype=np.uint8),
            "state": spaces.Box(-1.0, 1.0, shape=(N_STATE,), dtype=np.float32),
        }
    )


def markdown_table() -> str:
    """The schema as a Markdown table (the docs include it)."""
    rows = ["| key | index | name | meaning |", "|---|---|---|---|"]
    rows += [f'| `"map"` | {int(c)} | `{c.name}` | {CHANNELS[c]} |' for c in Channel]
    rows += [f'| `"state"` | {int(s)} | `{s.name}` | {STATES[s]} |' for s in State]
    return "\n".join(rows)


__all__ = [
    "BASE_CHANNELS",
    "CHANNELS",
    "CROP_CHANNELS",
    "Channel",
    "N_STATE",
    "STATES",
    "State",
    "markdown_table",
    "n_channels",
    "observation_space",
]
