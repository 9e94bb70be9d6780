"""The map's frame from the data (:mod:`digslam.observer.online.frame`): it holds every true position and
every cell a reading can reach, without a compass too; bad records get one line."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from digslam.observer.online.frame import FrameError, frame_cost, frame_of
from digslam.observer.record.mission import MissionRecord

sys.path.insert(0, str(Path(__file__).parent))
from test_mount import MOUNT, R_MAX, X0, mission  # noqa: E402


def test_the_frame_holds_the_truth_and_the_reach() -> None:
    rec, truth = mission(MOUNT, 2)
    g = frame_of(rec, X0, X0, max_range=R_MAX, resolution=0.1)
    reach = R_MAX + math.hypot(*MOUNT)
    for (x, y, _), _ in truth:
        assert g.lo[0] <= x - reach and x + reach <= g.hi[0]
        assert g.lo[1] <= y - reach and y + reach <= g.hi[1]
    assert np.allclose(g.cell_size, 0.1)
    assert frame_cost(g) == g.shape[0] * g.shape[1] * 11


def test_bad_records_get_one_line() -> None:
    rec, _ = mission(MOUNT, 2, n=5)
    with pytest.raises(FrameError, match="resolution"):
        frame_of(rec, X0, X0, max_range=R_MAX, resolution=0.0)
    with pytest.raises(FrameError, match="cells at"):
        frame_of(rec, X0, X0, max_range=R_MAX, resolution=1e-4, max_cells=10_000)
    wide = MissionRecord(**(rec.as_dict() | {"speed": np.tile([-np.inf, np.inf], (5, 1))}))
    with pytest.raises(FrameError, match="unbounded"):
        frame_of(wide, X0, X0, max_range=R_MAX, resolution=0.1)
    heading = np.tile([3.0, 3.1], (5, 1))
    heading[0] = 0.0  # then a compass half a turn away, with a yaw rate of 0.15 rad/s
    bad = MissionRecord(**(rec.as_dict() | {"heading": heading}))
    with pytest.raises(FrameError, match="contradict"):
        frame_of(bad, X0, X0, max_range=R_MAX, resolution=0.1)


def test_a_contradicted_record_is_framed_around_its_start_for_the_diagnosis() -> None:
    rec, _ = mission(MOUNT, 2, n=5)
    heading = np.tile([3.0, 3.1], (5, 1))
    heading[0] = 0.0
    bad = MissionRecord(**(rec.as_dict() | {"heading": heading}))
    g = frame_of(bad, X0, X0, max_range=R_MAX, resolution=0.1, contradicted=True)
    reach = R_MAX + math.hypot(*MOUNT)
    assert g.lo[0] <= X0[0] - reach and X0[0] + reach <= g.hi[0] and g.hi[0] - g.lo[0] < 2 * reach + 2.0
