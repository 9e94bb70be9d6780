"""Uncertain constants in a traced ``Function``: each occurrence is its own unknown value.

The backward pass contracts a node from all its uses, so two occurrences of an interval constant merged
into one node would be coupled: a feasible point could be removed (found with the bearings of Ex. 2.5,
where ``sin`` and ``cos`` of an angle in ``[42°, 48°]`` give the same interval).
"""

from __future__ import annotations

import numpy as np

from digslam.observer import Box, CtcFwdBwd, Function, Interval


def test_equal_interval_constants_stay_independent() -> None:
    c = Interval(0.0, 1.0)
    f = Function(lambda x: [x[0] - c, x[1] - Interval(0.0, 1.0)], n=2)  # x0 in c, x1 in another [0, 1]
    assert len([n for n in f.nodes if n[0] == "const"]) == 2
    ctc = CtcFwdBwd(f, Box([(0.0, 0.0), (0.0, 0.0)]))
    lo, hi = ctc.contract(np.array([[0.2, 0.8]]), np.array([[0.2, 0.8]]))  # feasible: 0.2 and 0.8 in [0, 1]
    assert np.array_equal(lo, [[0.2, 0.8]]) and np.array_equal(hi, [[0.2, 0.8]])
    # the same object twice is also two occurrences (interval semantics: [c] - [c] is not 0)
    g = Function(lambda x: [x[0] - c, x[1] - c], n=2)
    lo, hi = CtcFwdBwd(g, Box([(0.0, 0.0), (0.0, 0.0)])).contract(
        np.array([[0.2, 0.8]]), np.array([[0.2, 0.8]])
    )
    assert np.array_equal(lo, [[0.2, 0.8]])


def test_point_constants_still_merge() -> None:
    f = Function(lambda x: x[0] * 2.0 + x[1] * 2.0, n=2)
    assert len([n for n in f.nodes if n[0] == "const"]) == 1
