"""Do no harm: the gate that lets the prediction move the goal only where it claims a clear advantage.

At each plan, :class:`~.agent.PredictiveFrontierAgent` has two picks over the same candidate pixels: the
frontier agent's (:class:`~digslam.agents.baselines.frontier.FrontierAgent`: path, tier and turn less its
dark-share gain) and its own, the least *path per predicted gain* ``S`` (its ``"ratio"`` score). Where the
map predictor adds nothing, for example a single room whose walls are in sight or a building window whose
rooms are all seen, every frontier looks alike on the predicted map, and a departure from the frontier
agent's pick only costs time. The gate reads the predictive score of both picks and keeps the predictive
pick only when

    ``S(frontier pick) >= ratio * S(predictive pick) + margin``,

that is, when by the prediction's own measure the frontier agent's goal costs at least ``ratio`` times as
much path per unit of new free ground, plus ``margin`` (pixels of path). Otherwise the agent plans with the
frontier agent's costs, and does exactly what the frontier agent would.

The gate compares scores, not gains: on the rocks the predictive pick mostly wins by a shorter path to a
goal of about the same predicted gain (its gain is below the frontier pick's on half of the plans where
the two differ), so a gate on the gain alone would shut out most of what the prediction is good for.

The decision reads the observation's map and the prediction made from it, nothing else, so that two worlds
that give the same records give the same decisions; ``ratio`` and ``margin`` come from the agent's settings
(:mod:`.settings`, ``agents/configs/predictive_frontier.toml``), where they were chosen on validation levels.
``mode = "off"`` keeps the predictive pick always (the agent without a gate).

>>> gate = Gate("score_ratio", ratio=1.2, margin=0.5)
>>> gate.keeps_prediction(10.0, 13.0), gate.keeps_prediction(10.0, 12.4)
(True, False)
>>> Gate("off").keeps_prediction(1.0, 0.0)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: The gate's modes: ``"off"`` (always the predictive pick) and ``"score_ratio"`` (module docstring).
MODES = ("off", "score_ratio")


@dataclass(frozen=True)
class Gate:
    """The do-no-harm gate (module docstring).

    Args:
        mode: ``"score_ratio"`` or ``"off"``.
        ratio: How many times the predictive pick's score the frontier pick's must reach (>= 1).
        margin: Pixels of path (>= 0) the frontier pick's score must exceed that multiple by.
    """

    mode: str = "score_ratio"
    ratio: float = 1.0
    margin: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"gate: must be one of {', '.join(MODES)}, got {self.mode!r}")
        if not (isinstance(self.ratio, (int, float)) and math.isfinite(self.ratio) and self.ratio >= 1):
            raise ValueError(f"gate_ratio: must be finite and >= 1, got {self.ratio!r}")
        if not (isinstance(self.margin, (int, float)) and math.isfinite(self.margin) and self.margin >= 0):
            raise ValueError(f"gate_margin: must be finite and >= 0, got {self.margin!r}")

    def keeps_prediction(self, predictive_pick_score: float, frontier_pick_score: float) -> bool:
        """Whether the predictive pick stands: the frontier pick's predictive score (path per predicted gain,
        pixels) is at least ``ratio`` times the predictive pick's plus ``margin`` (always, with
        ``mode="off"``)."""
        if self.mode == "off":
            return True
        return bool(frontier_pick_score >= self.ratio * predictive_pick_score + self.margin)


__all__ = ["MODES", "Gate"]
