"""The thick map of explicit SLAM and its map function (thesis §6.2.1, Algorithm 6.1, Eq. 6.1–6.2, 6.16).

:class:`ThickMap` is the map ``[M] = [M⁻, M⁺]`` on a :class:`~digslam.observer.record.grid.Grid`, two
boolean rasters (every claim about whole cells), initially ``[∅, R^q]``. :class:`MapFunction` is the
bijective map function ``g_x`` that takes the map into the robot frame, ``Z = g_x(M)``, with its inverse and
their natural inclusion functions (the translation ``g_x(m) = m - x`` of Eq. 6.16 by default).

>>> m = ThickMap(Grid((-2.0, -2.0), (2.0, 2.0), (8, 8)))
>>> bool((m.codes() == PENUMBRA).all()), m.consistent()       # [∅, R^q]: every cell in the penumbra
(True, True)
>>> g = MapFunction.translation()
>>> [v.tolist() for v in g.image(np.array([[1.0, 1.0]]), np.array([[1.0, 1.0]]), np.array([[2.0, 3.0]]),
...                               np.array([[2.0, 3.0]]))]                   # m - x, outward rounded
[[[1.0, 2.0]], [[1.0, 2.0]]]
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Function
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digmap import DigMap
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

__all__ = ["MapFunction", "ThickMap"]


class ThickMap(DigMap):
    """The thick map ``[M] = [M⁻, M⁺]`` on a grid, initially ``[∅, R^q]`` (Algorithm 6.1, line 1).

    ``lower`` (``M⁻``, cells proved in ``M``) is the :class:`~.digmap.DigMap`'s ``free`` raster, so the
    closed-form digging (Eq. 6.21) and impact contractor (Eq. 6.22) of Dig-SLAM act on it directly;
    ``upper`` (``M⁺``) is False on the cells proved outside ``M``. Outside the grid ``[M] = [∅, R^q]``.
    """

    def __init__(self, grid: Grid) -> None:
        super().__init__(grid)
        self.upper = np.ones(grid.shape, dtype=bool)

    @property
    def lower(self) -> np.ndarray:
        """``M⁻`` (the same array as :attr:`free`)."""
        return self.free

    def codes(self) -> np.ndarray:
        """int8 codes of :mod:`digslam.observer.thick.cells`: CLEAR in ``M⁻``, DARK outside ``M⁺``,
        PENUMBRA between."""
        out = np.full(self.grid.shape, PENUMBRA, dtype=np.int8)
        out[self.free] = CLEAR
        out[~self.upper] = DARK
        return out

    def consistent(self) -> bool:
        """``M⁻ ⊂ M⁺``: False when the data contradict their bounds."""
        return not bool((self.free & ~self.upper).any())


class MapFunction:
    """A bijective map function ``g_x: R^q → R^q`` and its inverse (Eq. 6.1–6.2), with inclusion functions.

    Args:
        g: ``g(x, m)`` returning the ``q`` coordinates of ``g_x(m)`` (robot frame), built from the
            operations of :class:`~.expr.Function` (e.g. ``lambda x, m: [m[0] - x[0], m[1] - x[1]]``).
        g_inv: ``g_inv(x, z) = g_x⁻¹(z)``.
        n: the state dimension; q: the map dimension.
    """

    def __init__(self, g: Callable[..., Any] | None, g_inv: Callable[..., Any] | None, n: int = 2,
                 q: int = 2) -> None:  # fmt: skip
        self.n, self.q = int(n), int(q)
        self._exact_translation = g is None
        if g is not None:
            if g_inv is None:
                raise ValueError("g_inv: the inverse of g is needed (g must be bijective, Eq. 6.2)")
            n_, q_ = self.n, self.q

            def split(v: Any) -> tuple[list, list]:
                return [v[i] for i in range(n_)], [v[n_ + i] for i in range(q_)]

            self.g = Function(lambda v: g(*split(v)), n_ + q_)
            self.g_inv = Function(lambda v: g_inv(*split(v)), n_ + q_)
            if self.g.m != q_ or self.g_inv.m != q_:
                raise ValueError(f"g, g_inv: expected {q_} outputs, got {self.g.m} and {self.g_inv.m}")

    @classmethod
    def translation(cls) -> MapFunction:
        """``g_x(m) = m - x`` (Eq. 6.16), evaluated with outward-rounded subtractions."""
        return cls(None, None, 2, 2)

    def image(self, x_lo: np.ndarray, x_hi: np.ndarray, m_lo: np.ndarray, m_hi: np.ndarray) -> Batch:
        """Enclosure of ``g_[x]([m])`` for batches ``(N, n)`` and ``(N, q)``."""
        if self._exact_translation:
            return rnd.sub_down(m_lo, x_hi[:, :2]), rnd.sub_up(m_hi, x_lo[:, :2])
        r = self.g.eval((np.concatenate([x_lo, m_lo], 1), np.concatenate([x_hi, m_hi], 1)))
        return r.pair

    def preimage(self, x_lo: np.ndarray, x_hi: np.ndarray, z_lo: np.ndarray, z_hi: np.ndarray) -> Batch:
        """Enclosure of ``g_[x]⁻¹([z])``."""
        if self._exact_translation:
            return rnd.add_down(z_lo, x_lo[:, :2]), rnd.add_up(z_hi, x_hi[:, :2])
        r = self.g_inv.eval((np.concatenate([x_lo, z_lo], 1), np.concatenate([x_hi, z_hi], 1)))
        return r.pair
