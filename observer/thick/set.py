"""Contractors on thick sets (thesis §5.5.1–5.5.2, Eq. 5.44–5.46), acting on their separators.

A thick set ``[X] = [X⁻, X⁺]`` is represented by its :class:`~.sep.ThickSep`: the pair of
separators of ``X⁻`` and ``X⁺``; the set operations of Eq. 5.8–5.17 are its operators (``&``, ``|``,
``~``, ``-``, ``meet``, ``join``). Contracting a thick set moves its bounds inwards (Fig. 5.8):

>>> from digslam.observer import Box, SepBox
>>> from digslam.observer.thick.sep import ThickSep
>>> import numpy as np
>>> a = ThickSep(SepBox(Box([(0, 1), (0, 1)])), SepBox(Box([(0, 4), (0, 4)])))
>>> b = ThickSep(SepBox(Box([(2, 3), (2, 3)])), SepBox(Box([(-1, 3), (-1, 3)])))
>>> a2, b2 = ctc_subset(a, b)  # A ⊂ B: A⁺ shrinks to A⁺ ∩ B⁺, B⁻ grows to B⁻ ∪ A⁻
>>> a2.classify(np.array([[3.5, 3.5]]), np.array([[3.8, 3.8]])).tolist(), b2.classify(
...     np.array([[0.2, 0.2]]), np.array([[0.8, 0.8]])).tolist()
([-1], [1])
"""

from __future__ import annotations

from digslam.observer.sets.separators import SepInter, SepUnion
from digslam.observer.thick.sep import ThickSep


def ctc_subset(a: ThickSep, b: ThickSep) -> tuple[ThickSep, ThickSep]:
    """Minimal contractor of ``A ⊂ B``, ``A ∈ [A]``, ``B ∈ [B]`` (Prop. 5.1, Eq. 5.46).

    Returns:
        ``([A⁻, A⁺ ∩ B⁺], [B⁻ ∪ A⁻, B⁺])``.

    Raises:
        TypeError: if ``a`` or ``b`` is not a :class:`ThickSep`.
    """
    if not isinstance(a, ThickSep) or not isinstance(b, ThickSep):
        raise TypeError(f"ctc_subset: expected two ThickSep, got {type(a)} and {type(b)}")
    return ThickSep(a.lower, SepInter(a.upper, b.upper)), ThickSep(SepUnion(b.lower, a.lower), b.upper)


def ctc_equal(a: ThickSep, b: ThickSep) -> tuple[ThickSep, ThickSep]:
    """``A = B`` as ``A ⊂ B`` and ``B ⊂ A`` (Prop. 5.1 twice): both become ``[A⁻ ∪ B⁻, A⁺ ∩ B⁺]``."""
    a1, b1 = ctc_subset(a, b)
    b2, a2 = ctc_subset(b1, a1)
    return a2, b2


__all__ = ["ctc_equal", "ctc_subset"]
