"""``predictive_frontier``: the frontier agent whose expected gain is read on a predicted map.

The frontier agent (:class:`~digslam.agents.baselines.frontier.FrontierAgent`) ranks its candidate pixels by
path length, tier and turn, less ``gain_weight`` times an expected gain; there the gain is the dark share
around the pixel, blind to what lies in the dark. Here the gain is the free area a sensor would newly see
from the pixel on the map that a *map source* predicts (:func:`.gain_jit.visible_gain`, MapEx's estimated
visible area): the beams cross the predicted free probability ``p`` and count the dark and penumbra pixels,
each weighted by ``p - uncertainty * sqrt(p (1 - p))`` (the prediction less ``uncertainty`` standard
deviations of its Bernoulli free indicator), as a share of the square of side twice the sensor range (the
frontier gain's own scale). A dead end (a frontier that faces a wall the predictor expects) then loses to a
frontier that opens onto a room.

The candidate chosen is the one of least **path per predicted gain** (``score="ratio"``, the default):
``(c + path_offset) / (g + gain_floor)`` up to a constant, ``c`` the frontier agent's cost of the pixel
(path length, tier penalty and turn) and ``g`` its predicted gain. A near frontier with little behind it
still wins over a far one with a little more, and one that opens onto much new ground wins from farther
away. The cost less a multiple of the gain (``score="difference"``) makes the gain dominate the path
wherever the weight is large enough to matter, and the agent then criss-crosses an open room.

A map source has ``free(image) -> (p, var)``, ``(m, m)`` float arrays from the observation's uint8 map:

* :class:`~.model.Predictor`, the learned map predictor (observation only);
* :class:`TrueMap`, the diagnosis: the true certifiable reachable free share per pixel of the current level,
  read from the env's ground truth. An upper bound of what a perfect predictor would give this planner,
  **not an agent**: only the oracle diagnosis (:mod:`.oracle`) builds it.

**Do no harm** (:mod:`.gate`): at each plan the frontier agent's own pick (its costs, with its dark-share
gain) is computed beside the predictive one, and the predictive pick stands only where, by the prediction's
own path per gain, the frontier agent's pick is clearly worse; otherwise the agent plans with the frontier
agent's costs. The settings, the gate's thresholds included, come from
``agents/configs/predictive_frontier.toml`` (:mod:`.settings`).

**A tour** (``tour_weight > 0``): the costs the gate gives get the tour regret of
:class:`~digslam.agents.baselines.tour.TourFrontierAgent`, so that the goal starts the shortest open tour
over the frontier clusters instead of being the best goal alone.

The prediction is recomputed every ``predict_every`` steps (and on the first plan of an episode); every
claim still comes from the observer, so a wrong prediction costs time, never soundness.
"""

from __future__ import annotations

import inspect
import math
from typing import Any, Protocol

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import Memory, View
from digslam.agents.baselines.tour import TourFrontierAgent
from digslam.agents.prediction.gain_jit import visible_gain
from digslam.agents.prediction.gate import Gate
from digslam.envs.stack import observer_of

#: The frontier agent's own weight of its dark-share gain: the costs the gate falls back on are its costs.
FRONTIER_GAIN_WEIGHT: float = inspect.signature(FrontierAgent.__init__).parameters["gain_weight"].default


class MapSource(Protocol):
    """What :class:`PredictiveFrontierAgent` reads its map from."""

    def free(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(p, var)``: free probability and its variance per pixel of the ``(C, m, m)`` uint8 map."""
        ...


class TrueMap:
    """The true free share per map pixel of the env's current level (the oracle's map source; module
    docstring). ``env``: a ``digslam/DigCoverage*`` env (possibly wrapped) whose level is being played."""

    def __init__(self, env: gym.Env) -> None:
        try:
            self.layer = observer_of(env)
        except ValueError:
            raise ValueError("env: TrueMap needs a DigCoverage env (a GuaranteedObserver layer)") from None
        self._key: np.ndarray | None = None
        self._free = np.zeros((0, 0))

    def free(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        from digslam.agents.prediction.dataset import free_labels

        m = np.asarray(image).shape[-1]
        reach = self.layer.reachable
        if self._key is not reach or self._free.shape != (m, m):
            self._key, self._free = reach, free_labels(reach, m).astype(np.float64)
        return self._free, np.zeros_like(self._free)


class PredictiveFrontierAgent(TourFrontierAgent):
    """Frontier agent with the predicted visible gain (module docstring).

    Args:
        predictor: The map source (``free(image) -> (p, var)``); None loads the shipped map predictor
            (:func:`.model.load_shipped`).
        uncertainty: Standard deviations of the free indicator subtracted from each pixel's weight.
        predict_every: Steps between predictions.
        n_rays: Rays cast from each candidate pixel.
        predicted_weight: Weight (m) of the predicted gain in the ``"difference"`` score; 0 turns the
            prediction off in both scores (the frontier agent's costs).
        gain_weight: Weight (m) of the frontier agent's own dark-share gain, kept in ``c`` beside the
            predicted one; 0 (the default) replaces it.
        gain: ``"visible"`` (rays over the predicted map) or ``"area"`` (the predicted free share of the
            unknown pixels in the sensor range's square, no visibility).
        count: The pixels that count as new: ``"unknown"`` (dark and penumbra) or ``"dark"`` only.
        score: ``"ratio"`` (path per predicted gain) or ``"difference"`` (path less ``predicted_weight``
            times the gain; the module docstring says how they differ).
        path_offset: Added to ``c`` in the ratio (m; 10 pixels of the default 64-pixel map): how much a
            goal next to the robot still costs.
        gain_floor: Added to ``g`` in the ratio (a share): a candidate with no predicted gain costs its
            path times ``(gain_scale + gain_floor) / gain_floor``, not infinity.
        gain_scale: The gain (a share) at which the ratio equals ``c + path_offset`` (in pixels), so that
            the goal hysteresis (:func:`~digslam.agents.baselines.navigating.keep_bound`) keeps its meaning.
        gate: The do-no-harm gate (:class:`~.gate.Gate`); None: no gate (``Gate("off")``).
        tour_weight: Weight of the tour regret over the frontier clusters, added to the costs the gate
            gives (:class:`~digslam.agents.baselines.tour.TourFrontierAgent`); 0 (the default): one goal at a
            time.
        **kw: :class:`~digslam.agents.baselines.tour.TourFrontierAgent` and :class:`FrontierAgent`
            arguments.
    """

    def __init__(self, action_space: spaces.Space, observation_space: spaces.Space | None = None,
                 seed: int | None = None,
                 predictor: MapSource | None = None, uncertainty: float = 0.0, predict_every: int = 10,
                 n_rays: int = 32, predicted_weight: float = 160.0, gain_weight: float = 0.0,
                 gain: str = "visible", count: str = "unknown", score: str = "ratio",
                 path_offset: float = 3.125, gain_floor: float = 0.01, gain_scale: float = 0.1,
                 gate: Gate | None = None, tour_weight: float = 0.0, **kw: Any) -> None:  # fmt: skip
        if gain not in ("visible", "area") or count not in ("unknown", "dark"):
            raise ValueError(
                f"gain, count: must be 'visible'/'area' and 'unknown'/'dark', got {gain!r}, {count!r}"
            )
        if score not in ("ratio", "difference"):
            raise ValueError(f"score: must be 'ratio' or 'difference', got {score!r}")
        for name, v in (("path_offset", path_offset), ("gain_floor", gain_floor), ("gain_scale", gain_scale)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be finite and > 0, got {v!r}")
        if gate is not None and not isinstance(gate, Gate):
            raise ValueError(f"gate: expected a Gate (digslam.agents.prediction.gate), got {gate!r}")
        if gate is not None and gate.mode != "off" and score != "ratio":
            raise ValueError(f"gate: compares path per gain, so it needs score='ratio' (got {score!r}); "
                             "set gate='off' for another score")  # fmt: skip
        self.gate = gate if gate is not None else Gate("off")
        self.score, self.path_offset = score, float(path_offset)
        self.gain_floor, self.gain_scale = float(gain_floor), float(gain_scale)
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
        super().__init__(action_space, observation_space, seed, gain_weight=gain_weight,
                         tour_weight=tour_weight, **kw)  # fmt: skip

    def frontier_costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """The frontier agent's costs ``c`` (path length, tier, turn; in pixels) turned into the cost of the
        predicted gain ``g`` (:meth:`predicted_gain`) of every candidate:

        * ``score="ratio"``: path per gain, ``(max(c, 0) + path_offset) (gain_scale + gain_floor) / (g +
          gain_floor)``: the path length per unit of expected new area, scaled so that a candidate of gain
          ``gain_scale`` costs its path plus ``path_offset``;
        * ``score="difference"``: ``c - predicted_weight g``, over the pixel side.

        ``predicted_weight = 0`` leaves the frontier agent's costs as they are (no prediction). The gate
        (:meth:`gated`) then picks these costs or the frontier agent's."""
        cost = super().frontier_costs(view, mem, reach, dist)
        if self.predicted_weight <= 0:
            return cost
        px = self.px(cost.shape[0])
        cand = np.isfinite(cost)
        gain = self.predicted_gain(view, mem, cand)
        if self.score == "difference":
            out = cost - self.predicted_weight * gain / px
        else:
            out = np.full(cost.shape, np.inf)
            scale = (self.gain_scale + self.gain_floor) / (gain[cand] + self.gain_floor)
            out[cand] = (np.maximum(cost[cand], 0.0) + self.path_offset / px) * scale
        return self.gated(view, mem, cost, out)

    def gated(self, view: View, mem: Memory, cost: np.ndarray, predictive: np.ndarray) -> np.ndarray:
        """The costs to plan with: ``predictive`` where the gate keeps a predictive pick that differs from the
        frontier agent's, else the frontier agent's (``cost`` less the frontier agent's dark-share gain,
        :data:`FRONTIER_GAIN_WEIGHT`), so that a gate that never opens is the frontier agent, hysteresis
        included. The picks are the least costs off the robot's own pixel, as :meth:`_plan` takes them;
        the gate compares their ``predictive`` costs. Each decision is kept in ``mem.extra["gate"]``
        (True: the prediction's pick) and counted in ``mem.extra["gate_counts"]`` (``[kept, closed]``).
        With the gate off: always ``predictive``."""
        if self.gate.mode == "off":
            return predictive
        px = self.px(cost.shape[0])
        cand = np.isfinite(cost)
        frontier = cost - (FRONTIER_GAIN_WEIGHT - self.gain_weight) * self.expected_gain(view, mem, cand) / px
        picks = []
        for c in (predictive, frontier):
            c = c.copy()
            c[view.cell] = np.inf
            k = int(np.argmin(c))
            picks.append(k if math.isfinite(float(c.flat[k])) else -1)
        if min(picks) < 0 or picks[0] == picks[1]:
            return frontier  # no candidate, or the prediction does not move the pick
        keep = self.gate.keeps_prediction(float(predictive.flat[picks[0]]), float(predictive.flat[picks[1]]))
        mem.extra["gate"] = keep
        counts = mem.extra.setdefault("gate_counts", [0, 0])
        counts[0 if keep else 1] += 1
        return predictive if keep else frontier

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
        mem = self.memory(0)
        return None if mem is None or "pred" not in mem.extra else mem.extra["pred"][0]

    def predicted_gain(self, view: View, mem: Memory, candidates: np.ndarray) -> np.ndarray:
        """Predicted newly seen free area from each candidate pixel, as a share of the square of side twice
        the sensor range (module docstring); 0 off the candidates."""
        p, var = self.prediction(view, mem)
        m = view.clear.shape[0]
        radius = self.sensor_range / self.px(m)
        unknown = view.dark if self.count == "dark" else ~view.clear
        if self.gain_mode == "area":
            from scipy import ndimage

            weight = free_weight(p, var, self.uncertainty)
            k = 2 * int(round(radius)) + 1
            return ndimage.uniform_filter(np.where(unknown, weight, 0.0), size=k, mode="constant")
        rows, cols = np.nonzero(candidates)
        out = np.zeros((m, m))
        out[rows, cols] = visible_shares(view, p, var, rows, cols, radius, self.uncertainty, self.n_rays,
                                         unknown)  # fmt: skip
        return out


def free_weight(p: np.ndarray, var: np.ndarray, uncertainty: float) -> np.ndarray:
    """Each pixel's weight in the gain: ``p - uncertainty * sqrt(var)``, clipped to ``[0, 1]``."""
    return np.clip(p - uncertainty * np.sqrt(np.maximum(var, 0.0)), 0.0, 1.0)


def visible_shares(view: View, p: np.ndarray, var: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                   radius: float, uncertainty: float = 0.0, n_rays: int = 32,
                   unknown: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """``(K,)`` predicted newly seen free area from the pixels ``(rows[k], cols[k])`` of ``view``'s map, as a
    share of the square of side ``2 radius`` (pixels): :func:`.gain_jit.visible_gain` over the prediction
    ``(p, var)`` (clear pixels let every beam through), each ``unknown`` pixel (default: not clear) weighted
    by :func:`free_weight`."""
    rows = np.asarray(rows, np.int64).reshape(-1)
    cols = np.asarray(cols, np.int64).reshape(-1)
    if not len(rows):
        return np.zeros(0)
    pass_p = np.where(view.clear, 1.0, np.clip(p, 0.0, 1.0))
    unknown = ~view.clear if unknown is None else unknown
    weight = free_weight(p, var, uncertainty)
    g = visible_gain(pass_p, weight, unknown, rows, cols, float(radius), n_rays, 0.5)
    return g / (2.0 * radius) ** 2


__all__ = ["MapSource", "PredictiveFrontierAgent", "TrueMap", "free_weight", "visible_shares"]
