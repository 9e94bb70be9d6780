"""``predictive_frontier``: the frontier agent whose expected gain is read on a predicted map.

The frontier agent (:class:`~digslam.agents.baselines.frontier.FrontierAgent`) ranks its candidate pixels by
path length, tier and turn, less ``gain_weight`` times an expected gain; there the gain is the dark share
around the pixel, blind to what lies in the dark. Here it is the free area a sensor would newly see from
the pixel on the map that a *map source* predicts (:func:`.gain_jit.visible_gain`, MapEx's estimated
visible area): the beams cross the predicted free probability ``p`` and count the dark and penumbra pixels,
each weighted by ``p - uncertainty * sqrt(p (1 - p))`` (the prediction less ``uncertainty`` standard
deviations of its Bernoulli free indicator), as a share of the square of side twice the sensor range (the
frontier gain's own scale). A dead end (a frontier that faces a wall the predictor expects) then loses to a
frontier that opens onto a room.

A map source has ``free(image) -> (p, var)``, ``(m, m)`` float arrays from the observation's uint8 map:

* :class:`~.model.Predictor`, the learned map predictor (observation only);
* :class:`TrueMap`, the diagnosis: the true certifiable reachable free share per pixel of the current level,
  read from the env's ground truth. An upper bound of what a perfect predictor would give this planner,
  **not an agent**: only the oracle diagnosis (:mod:`.oracle`) builds it.

The prediction is recomputed every ``predict_every`` steps (and on the first plan of an episode); every
claim still comes from the observer, so a wrong prediction costs time, never soundness.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import Memory, View
from digslam.agents.prediction.gain_jit import visible_gain


class MapSource(Protocol):
    """What :class:`PredictiveFrontierAgent` reads its map from."""

    def free(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(p, var)``: free probability and its variance per pixel of the ``(C, m, m)`` uint8 map."""
        ...


class TrueMap:
    """The true free share per map pixel of the env's current level (the oracle's map source; module
    docstring). ``env``: a ``digslam/DigCoverage*`` env (possibly wrapped) whose level is being played."""

    def __init__(self, env: Any) -> None:
        from digslam.agents.baselines.registry import observer_layer

        self.layer = observer_layer(env)
        if self.layer is None:
            raise ValueError("env: TrueMap needs a DigCoverage env (a GuaranteedObserver layer)")
        self._key: Any = None
        self._free = np.zeros((0, 0))

    def free(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        from digslam.agents.prediction.dataset import free_labels

        m = np.asarray(image).shape[-1]
        reach = self.layer.reachable
        if self._key is not reach or self._free.shape != (m, m):
            self._key, self._free = reach, free_labels(reach, m).astype(np.float64)
        return self._free, np.zeros_like(self._free)


class PredictiveFrontierAgent(FrontierAgent):
    """Frontier agent with the predicted visible gain (module docstring).

    Args:
        predictor: The map source (``free(image) -> (p, var)``); None loads the shipped map predictor
            (:func:`.model.load_shipped`).
        uncertainty: Standard deviations of the free indicator subtracted from each pixel's weight.
        predict_every: Steps between predictions.
        n_rays: Rays cast from each candidate pixel.
        predicted_weight: Weight (m) of the predicted gain. On the validation levels with the true map (6 per
            generator), 160 beat 20 and 80 (geometric-mean speedup over the frontier agent 1.086, against
            0.885 and 1.079).
        gain_weight: Weight (m) of the frontier agent's own dark-share gain, kept beside the predicted one;
            0 (the default) replaces it (with 40 beside 80: 1.031 on the same levels).
        gain: ``"visible"`` (rays over the predicted map) or ``"area"`` (the predicted free share of the
            unknown pixels in the sensor range's square, no visibility: 0.971 there).
        count: The pixels that count as new: ``"unknown"`` (dark and penumbra) or ``"dark"`` only (0.952).
        **kw: :class:`FrontierAgent` arguments.
    """

    def __init__(self, action_space: Any, observation_space: Any = None, seed: int | None = None,
                 predictor: MapSource | None = None, uncertainty: float = 0.0, predict_every: int = 10,
                 n_rays: int = 32, predicted_weight: float = 160.0, gain_weight: float = 0.0,
                 gain: str = "visible", count: str = "unknown", **kw: Any) -> None:  # fmt: skip
        if gain not in ("visible", "area") or count not in ("unknown", "dark"):
            raise ValueError(
                f"gain, count: must be 'visible'/'area' and 'unknown'/'dark', got {gain!r}, {count!r}"
            )
        self.gain_mode, self.count = gain, count
        self.predicted_weight = float(predicted_weight)
        if not (math.isfinite(uncertainty) and uncertainty >= 0):
            raise ValueError(f"uncertainty: must be finite and >= 0, got {uncertainty!r}")
        for name, v in (("predict_every", predict_every), ("n_rays", n_rays)):
            if not (isinstance(v, int) and v >= 1):
                raise ValueError(f"{name}: must be an integer >= 1, got {v!r}")
        if predictor is None:
            from digslam.agents.prediction.model import load_shipped

            predictor = load_shipped()
        if not callable(getattr(predictor, "free", None)):
            raise ValueError("predictor: expected a map source with a free(image) method")
        self.predictor = predictor
        self.uncertainty, self.predict_every, self.n_rays = float(uncertainty), predict_every, n_rays
        super().__init__(action_space, observation_space, seed, gain_weight=gain_weight, **kw)

    def frontier_costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """The frontier agent's costs less ``predicted_weight`` times the predicted gain
        (:meth:`predicted_gain`) over the pixel side."""
        cost = super().frontier_costs(view, mem, reach, dist)
        if self.predicted_weight > 0:
            cost -= (
                self.predicted_weight
                * self.predicted_gain(view, mem, np.isfinite(cost))
                / self.px(cost.shape[0])
            )
        return cost

    def prediction(self, view: View, mem: Memory) -> tuple[np.ndarray, np.ndarray]:
        """``(p, var)`` of the current map, recomputed every ``predict_every`` steps."""
        x = mem.extra
        if "pred" not in x or mem.t - x["pred_t"] >= self.predict_every:
            if view.image is None:
                raise ValueError("view: the predictive agent needs the observation's map (View.image)")
            p, var = self.predictor.free(view.image)
            x["pred"], x["pred_t"] = (np.asarray(p, np.float64), np.asarray(var, np.float64)), mem.t
        return x["pred"]

    def shown_prediction(self) -> np.ndarray | None:
        """The free probabilities of the last prediction for the first env (what a demo draws), or None."""
        mem = self._mem.get(0)
        return None if mem is None or "pred" not in mem.extra else mem.extra["pred"][0]

    def predicted_gain(self, view: View, mem: Memory, candidates: np.ndarray) -> np.ndarray:
        """Predicted newly seen free area from each candidate pixel, as a share of the square of side twice
        the sensor range (module docstring); 0 off the candidates."""
        p, var = self.prediction(view, mem)
        m = view.clear.shape[0]
        radius = self.sensor_range / self.px(m)
        pass_p = np.where(view.clear, 1.0, np.clip(p, 0.0, 1.0))
        weight = np.clip(p - self.uncertainty * np.sqrt(np.maximum(var, 0.0)), 0.0, 1.0)
        unknown = view.dark if self.count == "dark" else ~view.clear
        if self.gain_mode == "area":
            from scipy import ndimage

            k = 2 * int(round(radius)) + 1
            return ndimage.uniform_filter(np.where(unknown, weight, 0.0), size=k, mode="constant")
        rows, cols = np.nonzero(candidates)
        out = np.zeros((m, m))
        if len(rows):
            g = visible_gain(pass_p, weight, unknown, rows.astype(np.int64), cols.astype(np.int64),
                             float(radius), self.n_rays, 0.5)  # fmt: skip
            out[rows, cols] = g / (2.0 * radius) ** 2
        return out


__all__ = ["MapSource", "PredictiveFrontierAgent", "TrueMap"]
