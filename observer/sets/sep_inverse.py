"""Separator for ``f⁻¹(Y)`` by forward-backward propagation (thesis §2.4.4, Theorem 2.1, Eq. 2.62).

One forward pass evaluates ``f`` on the batch; backward passes then project ``Y`` (for ``x_out``)
and the closed complement of ``Y`` (for ``x_in``) back onto the boxes. ``Y`` is an interval, a box,
or any separator in the image space. When ``f`` has a :class:`~.tape_jit.Tape` (no trigonometric,
``min``/``max`` or ``atan2`` node) the whole batch is separated by compiled kernels
(:mod:`.hc4_jit`); otherwise by the numpy forward-backward of :mod:`.contractors`.

>>> ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
>>> xin, xout = ring(Box([(3.1, 3.2), (2.4, 2.6)]))        # inside the ring of Ex. 2.7
>>> bool(xin.is_empty().all()), bool(xout.is_empty().any())
(True, False)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.core.boxes import chunked, empty_rows, normalize_empty
from digslam.observer.core.types import Batch, Pair
from digslam.observer.expr.centred import centred_image
from digslam.observer.expr.centred_ctc import centred_contract
from digslam.observer.expr.expr import Function
from digslam.observer.expr.hc4_jit import hc4, image, sep_box
from digslam.observer.expr.tape_jit import Tape
from digslam.observer.sets.contractors import forward, hc4_backward
from digslam.observer.sets.separators import Sep, SepBox, hull_batch, inter_batch


class SepInverse(Sep):
    """Separator of ``{x | f(x) ∈ Y}``.

    Args:
        f: a :class:`~.expr.Function` ``Rⁿ → Rᵐ`` (or a callable, traced into one).
        y: an interval or number (``m = 1``), a box of dimension ``m``, or a :class:`Sep` on ``Rᵐ``.

        centred: intersect ``f``'s natural enclosure with its centred (mean-value) form before the
            backward passes (:mod:`.centred`, Eq. 2.20), then contract both parts once more by the
            centred backward pass (:mod:`.centred_ctc`): ``x_out`` with ``f(x) ∈ Y``, ``x_in`` with
            each half-line of the complement of ``Y`` (hull of the pieces). Fewer bisections near the
            boundary when variables occur several times, and sharper projections (:class:`.SepProj`);
            off by default (measured in ``tests/observer/expr/test_centred.py``).

    Raises:
        ValueError: if ``y``'s dimension is not ``m``.
    """

    def __init__(self, f: Function | Callable[..., Any], y: Any, centred: bool = False) -> None:
        self.centred = bool(centred)
        self.f = f if isinstance(f, Function) else Function(f)
        self.n = self.f.n
        self.sep_y: Sep | None
        if isinstance(y, Sep):
            if y.n is not None and y.n != self.f.m:
                raise ValueError(f"y: separator of dimension {y.n}, but f has {self.f.m} outputs")
            self.sep_y, self.box = y, None
        else:
            box = SepBox(y)
            if box.n != self.f.m:
                raise ValueError(f"y: box of dimension {box.n}, but f has {self.f.m} outputs")
            self.sep_y, self.box = None, box
            self._y = np.stack(box.box).astype(np.float64)

    def image(self, vals: list[tuple[np.ndarray, np.ndarray]], n_rows: int) -> Batch:
        """The forward image ``[f]([x])`` as an ``(N, m)`` batch."""
        outs = [vals[o] for o in self.f.outputs]
        ylo = np.stack([np.broadcast_to(o[0], (n_rows,)) for o in outs], axis=1)
        yhi = np.stack([np.broadcast_to(o[1], (n_rows,)) for o in outs], axis=1)
        return ylo, yhi

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        tape = Tape.of(self.f)
        if tape is None:
            return chunked(self._separate, lo, hi)
        if self.box is not None:
            res = sep_box(tape, lo, hi, self._y, self.centred)
            return self._centred_parts((res[0], res[1]), (res[2], res[3]))
        ylo, yhi = image(tape, lo, hi)
        if self.centred:
            ylo, yhi = inter_batch((ylo, yhi), centred_image(self.f, lo, hi))
        assert self.sep_y is not None  # no box: y is a separator
        yin, yout = self.sep_y.separate(ylo, yhi)
        return hc4(tape, lo, hi, *yin, centred=self.centred), hc4(tape, lo, hi, *yout, centred=self.centred)

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        tape = Tape.of(self.f)
        if tape is not None and self.box is not None and not self.centred:
            return sep_box(tape, lo, hi, self._y, self.centred)
        return super().separate_stacked(lo, hi)

    def _centred_parts(self, xin: Batch, xout: Batch) -> tuple[Batch, Batch]:
        """With ``centred`` and a box ``Y``: both parts contracted once more by the centred backward pass
        (:func:`.centred_ctc.centred_contract`); ``x_in`` piece by piece of the complement of ``Y``."""
        if not self.centred or self.box is None:
            return xin, xout
        m, N = self.f.m, xin[0].shape[0]
        ylo, yhi = np.broadcast_to(self._y[0], (N, m)), np.broadcast_to(self._y[1], (N, m))
        xout = centred_contract(self.f, *xout, ylo, yhi)
        acc = (np.full_like(xin[0], np.inf), np.full_like(xin[1], -np.inf))
        for j in range(m):
            for side in (0, 1):
                plo, phi = np.full((N, m), -np.inf), np.full((N, m), np.inf)
                if side == 0:
                    phi[:, j] = ylo[:, j]
                else:
                    plo[:, j] = yhi[:, j]
                acc = hull_batch(acc, centred_contract(self.f, *xin, plo, phi))
        return normalize_empty(*acc), normalize_empty(*xout)

    def _separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        vals = forward(self.f, lo, hi, self.centred)
        if self.box is None:
            assert self.sep_y is not None
            yin, yout = self.sep_y.separate(*self.image(vals, lo.shape[0]))
            return hc4_backward(self.f, vals, yin, lo, hi), hc4_backward(self.f, vals, yout, lo, hi)
        xout = hc4_backward(self.f, vals, self.box.box, lo, hi)
        xin = self._in_pieces(vals, lo, hi)
        return self._centred_parts(xin, xout)

    def _in_pieces(self, vals: list[Pair], lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``x_in`` of the numpy path: the hull of the backward projections of the complement's pieces."""
        assert self.box is not None
        xin = (np.full_like(lo, np.inf), np.full_like(hi, -np.inf))
        for plo, phi in self.box.pieces(*self.image(vals, lo.shape[0])):
            live = plo[:, 0] <= phi[:, 0]
            if live.all():
                xin = hull_batch(xin, hc4_backward(self.f, vals, (plo, phi), lo, hi))
            elif live.any():  # project the piece through the rows that meet it only
                r = np.flatnonzero(live)
                sub = [(v[0][r], v[1][r]) for v in vals]
                plo_r, phi_r = hc4_backward(self.f, sub, (plo[r], phi[r]), lo[r], hi[r])
                xin[0][r] = np.minimum(xin[0][r], plo_r)
                xin[1][r] = np.maximum(xin[1][r], phi_r)
        dead = empty_rows(*self.image(vals, lo.shape[0])) & ~empty_rows(lo, hi)
        if dead.any():  # f defined nowhere on the box: all of it is outside f⁻¹(Y)
            xin[0][dead], xin[1][dead] = lo[dead], hi[dead]
        return xin


__all__ = [
    "SepInverse",
]
