"""The map predictor's gains as features of the goal env's candidates (the learned chooser's inputs).

:class:`PredictedGain` is the entry point :data:`ENTRY_POINT` of ``candidate_features``
(:mod:`digslam.agents.goals.extra`): ``GoalSelectionEnv(candidate_features=ENTRY_POINT)`` and the
:class:`~digslam.agents.goals.GoalAgent` that replays it append two features to every candidate:

* ``predicted_gain``: ``tanh(SCALE * g)``, where ``g`` is the predicted newly seen free area from the
  candidate's goal pixel (the robot's pixel for the turn in place) as a share of the square of side twice
  the sensor range, what ``predictive_frontier`` ranks its goals by (:func:`.agent.visible_shares`,
  uncertainty 0; typical frontier values 0.02-0.1, hence :data:`SCALE`);
* ``predicted_spread``: the same of how much of ``g`` one standard deviation of each pixel's free indicator
  takes away (the gain at uncertainty 0 less at uncertainty 1), the uncertainty of the gain.

The prediction is the shipped map predictor's (:func:`.model.load_shipped`) on the decision's observation:
the chooser that reads these features reads the observation and nothing else.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.agents.baselines.policy import View
from digslam.agents.goals.candidates import Candidates
from digslam.agents.goals.driver import GoalDriver
from digslam.agents.prediction.agent import MapSource, visible_shares

#: The entry point that names :class:`PredictedGain` in a goal env's keywords and a model's sidecar.
ENTRY_POINT = "digslam.agents.prediction.features:PredictedGain"
#: Factor on the gain shares before the ``tanh``.
SCALE = 10.0


class PredictedGain:
    """Predicted gain and its spread per candidate (module docstring).

    Args:
        predictor: The map source (``free(image) -> (p, var)``); None: the shipped map predictor, loaded on
            first use.
        n_rays: Rays cast from each goal pixel.
    """

    names = ("predicted_gain", "predicted_spread")

    def __init__(self, predictor: MapSource | None = None, n_rays: int = 32) -> None:
        self.predictor, self.n_rays = predictor, int(n_rays)

    def __deepcopy__(self, memo: dict[int, Any]) -> PredictedGain:
        return self  # no per-episode state (the look-ahead teacher copies whole envs)

    def __call__(self, driver: GoalDriver, view: View, candidates: Candidates) -> np.ndarray:
        """``(n, 2)`` float32 features of ``candidates`` on ``view`` (zero on the padding)."""
        if self.predictor is None:
            from digslam.agents.prediction.model import load_shipped

            self.predictor = load_shipped()
        if view.image is None:
            raise ValueError("view: the predicted gain needs the observation's map (View.image)")
        out = np.zeros((len(candidates.mask), 2), np.float32)
        slots = np.flatnonzero(candidates.mask)
        if not len(slots):
            return out
        p, var = self.predictor.free(view.image)
        radius = driver.sensor_range / driver.px(view.clear.shape[0])
        rows, cols = candidates.goal[slots, 0], candidates.goal[slots, 1]
        mean = visible_shares(view, p, var, rows, cols, radius, 0.0, self.n_rays)
        low = visible_shares(view, p, var, rows, cols, radius, 1.0, self.n_rays)
        out[slots, 0], out[slots, 1] = np.tanh(SCALE * mean), np.tanh(SCALE * (mean - low))
        return out


__all__ = ["ENTRY_POINT", "SCALE", "PredictedGain"]
