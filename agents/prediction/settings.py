"""The settings of ``predictive_frontier``, read from a TOML file: the shipped agent is its file.

:class:`PredictiveSettings` holds every knob of :class:`~.agent.PredictiveFrontierAgent` that was chosen on
validation levels: the score and its constants, the prediction's cadence and rays, the do-no-harm gate
(:mod:`.gate`: ``gate``, ``gate_ratio``, ``gate_margin``) and the weight of the tour over the frontier
clusters (``tour_weight``). The shipped values live in
``agents/configs/predictive_frontier.toml`` (:data:`SHIPPED_SETTINGS`), whose comments say on how many
levels each was chosen; :func:`~digslam.agents.prediction.make_predictive` reads that file unless it is
given another, so the thresholds are data, not constants of the code. An unknown key or a bad value fails
in one line that names it.

>>> s = load_settings()
>>> s.kind, s.make_gate().mode in ("off", "score_ratio")
('predictive_frontier', True)
>>> PredictiveSettings.from_dict({"gate_ratio": 0.5})
Traceback (most recent call last):
ValueError: gate_ratio: must be finite and >= 1, got 0.5
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from digslam.agents.prediction.gate import Gate
from digslam.observer.core.config import (
    Config,
    check,
    check_choice,
    check_finite_nonneg,
    check_finite_pos,
    check_int,
    config_dataclass,
)

#: The value of ``kind`` that marks the agent's settings.
KIND = "predictive_frontier"
#: The shipped agent's settings.
SHIPPED_SETTINGS = Path(__file__).resolve().parents[1] / "configs" / "predictive_frontier.toml"


@config_dataclass
class PredictiveSettings(Config):
    """The agent's settings (module docstring; :class:`~.agent.PredictiveFrontierAgent` says what each
    does). ``gate``, ``gate_ratio`` and ``gate_margin`` are the gate's ``mode``, ``ratio`` and ``margin``
    (:class:`~.gate.Gate`)."""

    kind: str = KIND
    score: str = "ratio"
    gain: str = "visible"
    count: str = "unknown"
    path_offset: float = 3.125
    gain_floor: float = 0.01
    gain_scale: float = 0.1
    uncertainty: float = 0.0
    predict_every: int = 10
    n_rays: int = 32
    gate: str = "off"
    gate_ratio: float = 1.0
    gate_margin: float = 0.0
    tour_weight: float = 0.0

    def __post_init__(self) -> None:
        check(self.kind == KIND, "kind", f'must be "{KIND}", got {self.kind!r}')
        check_choice("score", self.score, ("ratio", "difference"))
        check_choice("gain", self.gain, ("visible", "area"))
        check_choice("count", self.count, ("unknown", "dark"))
        for name in ("path_offset", "gain_floor", "gain_scale"):
            check_finite_pos(name, getattr(self, name))
        check_finite_nonneg("uncertainty", self.uncertainty)
        check_finite_nonneg("tour_weight", self.tour_weight)
        for name in ("predict_every", "n_rays"):
            check_int(name, getattr(self, name), 1)
        self.make_gate()  # the gate's own checks, in its words
        why = f'compares path per gain, so it needs score = "ratio" (got {self.score!r}); set gate = "off"'
        check(self.gate == "off" or self.score == "ratio", "gate", why)

    def make_gate(self) -> Gate:
        """The :class:`~.gate.Gate` these settings describe."""
        return Gate(self.gate, self.gate_ratio, self.gate_margin)

    def agent_kwargs(self) -> dict[str, Any]:
        """The :class:`~.agent.PredictiveFrontierAgent` keywords."""
        d = {k: v for k, v in self.to_dict().items() if k not in ("kind", "gate_ratio", "gate_margin")}
        return {**d, "gate": self.make_gate()}


def load_settings(path: str | Path | None = None, overrides: Iterable[str] = ()) -> PredictiveSettings:
    """The settings in ``path`` (None: :data:`SHIPPED_SETTINGS`), with ``key=value`` ``overrides``;
    ``ValueError`` in one line naming the file or the key."""
    return PredictiveSettings.from_file(SHIPPED_SETTINGS if path is None else path, overrides)


__all__ = ["KIND", "SHIPPED_SETTINGS", "PredictiveSettings", "load_settings"]
