"""The codes of a cell classified against a thick set ``[X⁻, X⁺]`` (thesis Eq. 5.4, §5.3).

A thick set splits space into the clear zone ``X⁻``, the penumbra ``X⁺ \\ X⁻`` and the dark zone
``complement(X⁺)``. A classified box or grid cell carries one int8 code:

* :data:`CLEAR` (1): the box is proved inside ``X⁻``;
* :data:`PENUMBRA` (2): proved inside ``X⁺`` and proved outside ``X⁻``;
* :data:`DARK` (-1): proved outside ``X⁺``;
* :data:`UNKNOWN` (0): nothing is proved (the box straddles a boundary).

No code other than UNKNOWN is given without proof. These are the codes of :class:`.sep.ThickSep`, of the
explored zone (:mod:`digslam.observer.slam.explored`), of the online observer's map and of the sets the
environments show an agent. (The thick Boolean's unknown, ``-1``, is :data:`.interval.UNKNOWN`, another
type.)
"""

from __future__ import annotations

import numpy as np

CLEAR, DARK, PENUMBRA, UNKNOWN = np.int8(1), np.int8(-1), np.int8(2), np.int8(0)

__all__ = ["CLEAR", "DARK", "PENUMBRA", "UNKNOWN"]
