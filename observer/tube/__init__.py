"""Tubes (Sec. 6.2, App. B): boxes over time that hold a trajectory.

Lives here: :mod:`.tube` (``Tube``, dead reckoning, headings from compass and gyro) and :mod:`.ctc` (the
derivative contractor and the velocity models: unicycle, body-frame velocity ``x' = R(psi) v``, Eq.
3.59/B.20).

May import: :mod:`digslam.observer.core`; numpy.
"""

from .ctc import body_velocity, unicycle_velocity
from .tube import Tube, ctc_deriv, dead_reckoning, heading_from_compass, heading_from_gyro

__all__ = [
    "body_velocity",
    "ctc_deriv",
    "dead_reckoning",
    "heading_from_compass",
    "heading_from_gyro",
    "unicycle_velocity",
    "Tube",
]
