"""How good a map prediction is, on the pixels the input leaves open (dark or penumbra).

:func:`scores` compares free probabilities ``p`` with the labels (the true free share of each pixel,
:mod:`.dataset`; a pixel counts as free when at least half of it is) on the pixels that are dark or penumbra
in the input map:

* ``accuracy``: share of those pixels where ``p >= 0.5`` agrees with the label;
* ``iou``: intersection over union of the predicted and the true free pixels;
* ``ece``: expected calibration error, the mean over ten equal-width bins of ``p`` of
  ``|mean p - mean label|``, weighted by the bin's share of the pixels (the label as a share, not rounded).

:func:`baselines` gives the two references: ``base_rate`` (every open pixel free with the training set's
free share among open pixels) and ``dilate`` (an open pixel is free when it lies within ``DILATE`` pixels of
the clear area, the "the room goes on a little" guess).

>>> p = np.array([[0.9, 0.2], [0.6, 0.4]]); label = np.array([[1.0, 0.0], [0.0, 1.0]])
>>> s = scores(p[None], label[None], np.ones((1, 2, 2), bool))
>>> round(s["accuracy"], 2), round(s["iou"], 3)
(0.5, 0.333)
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from digslam.envs.observation import Channel

#: Pixels of the ``dilate`` baseline.
DILATE = 3
#: Bins of the calibration error.
ECE_BINS = 10


def open_pixels(maps: np.ndarray) -> np.ndarray:
    """``(N, m, m)`` bool: the pixels that are dark or penumbra in ``(N, C, m, m)`` uint8 maps."""
    return np.asarray(maps)[:, Channel.CLEAR] <= 127


def scores(p: np.ndarray, label: np.ndarray, where: np.ndarray) -> dict[str, float]:
    """Accuracy, IoU and ECE of ``p`` against ``label`` on the pixels ``where`` (module docstring)."""
    pv, lv = np.asarray(p, np.float64)[where], np.asarray(label, np.float64)[where]
    if pv.size == 0:
        return {"accuracy": float("nan"), "iou": float("nan"), "ece": float("nan"), "pixels": 0.0}
    pred, true = pv >= 0.5, lv >= 0.5
    union = np.count_nonzero(pred | true)
    bins = np.minimum((pv * ECE_BINS).astype(int), ECE_BINS - 1)
    sp = np.bincount(bins, weights=pv, minlength=ECE_BINS)
    sl = np.bincount(bins, weights=lv, minlength=ECE_BINS)
    ece = float(np.abs(sp - sl).sum() / pv.size)
    return {"accuracy": float(np.mean(pred == true)),
            "iou": float(np.count_nonzero(pred & true) / union) if union else 1.0,
            "ece": ece, "pixels": float(pv.size)}  # fmt: skip


def base_rate(maps: np.ndarray, labels: np.ndarray) -> float:
    """The free share of the open pixels of a (training) set."""
    where = open_pixels(maps)
    return float(np.asarray(labels)[where].mean()) if where.any() else 0.5


def baselines(maps: np.ndarray, rate: float) -> dict[str, np.ndarray]:
    """``(N, m, m)`` free probabilities of the two reference guesses (module docstring)."""
    clear = np.asarray(maps)[:, Channel.CLEAR] > 127
    near = ndimage.binary_dilation(clear, structure=np.ones((1, 2 * DILATE + 1, 2 * DILATE + 1), bool))
    return {"base_rate": np.full(clear.shape, float(rate)), "dilate": near.astype(np.float64)}


def report(p: np.ndarray, maps: np.ndarray, labels: np.ndarray, generators: np.ndarray,
           rate: float) -> dict[str, dict[str, dict[str, float]]]:  # fmt: skip
    """``{generator or "all": {"predictor" | "base_rate" | "dilate": scores}}`` on the open pixels."""
    where = open_pixels(maps)
    refs = baselines(maps, rate)
    out: dict[str, dict[str, dict[str, float]]] = {}
    gens = np.asarray(generators)
    for g in [*sorted(set(gens.tolist())), "all"]:
        sel = np.ones(len(gens), bool) if g == "all" else gens == g
        out[g] = {"predictor": scores(p[sel], labels[sel], where[sel])}
        for name, q in refs.items():
            out[g][name] = scores(q[sel], labels[sel], where[sel])
    return out


__all__ = ["DILATE", "ECE_BINS", "base_rate", "baselines", "open_pixels", "report", "scores"]
