"""The polar constraint as contractors and separators (Ch. 4): range-bearing measurements.

Lives here: :mod:`.ctc` (``CtcPolar``, the minimal polar contractor, Sec. 4.3.2, running the kernels of
:mod:`digslam.observer.core.polar_jit`) and :mod:`.sep` (``SepPolarXY``, ``SepPi``/``SepPiInv`` for sonar
cones, ``SepLandmark``, Sec. 4.3-4.4).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.expr`, :mod:`digslam.observer.sets`; numpy.
"""

from .ctc import CtcPolar
from .sep import (
    SepCtcPreimage,
    SepLandmark,
    SepPi,
    SepPiInv,
    SepPolarXY,
    complement_boxes,
    sep_landmark_fwdbwd,
)

__all__ = [
    "complement_boxes",
    "sep_landmark_fwdbwd",
    "CtcPolar",
    "SepCtcPreimage",
    "SepLandmark",
    "SepPi",
    "SepPiInv",
    "SepPolarXY",
]
