"""Snapshots for the map predictor: labels from the world's raster, resumable files, no test levels."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.agents.prediction import dataset


def test_free_labels_are_block_shares():
    rng = np.random.default_rng(0)
    reach = rng.random((128, 128)) < 0.7
    lab = dataset.free_labels(reach, 64)
    np.testing.assert_allclose(lab, reach.reshape(64, 2, 64, 2).mean(axis=(1, 3)), rtol=1e-6)
    odd = dataset.free_labels(reach[:127, :127], 64)  # uneven blocks: every share in [0, 1], a cell's weight
    assert odd.shape == (64, 64) and 0 <= odd.min() and odd.max() <= 1


def test_generate_writes_one_file_a_level_and_resumes(tmp_path):
    paths = dataset.generate(tmp_path, ["room", "caves"], [0], progress=False, steps=80, every=40)
    assert [p.name for p in paths] == ["room_0.npz", "caves_0.npz"]
    stamp = [p.stat().st_mtime_ns for p in paths]
    again = dataset.generate(tmp_path, ["room", "caves"], [0], progress=False, steps=80, every=40)
    assert [p.stat().st_mtime_ns for p in again] == stamp  # nothing regenerated
    d = dataset.load(paths)
    assert d["map"].dtype == np.uint8 and d["map"].shape[1:] == (4, 64, 64)
    assert d["free"].shape == (len(d["map"]), 64, 64) and set(d["generator"]) == {"room", "caves"}
    with np.load(paths[0]) as f:  # the label is the world's, the input the observer's: clear pixels are free
        clear = f["map"][:, 0] > 127
        assert np.all(np.broadcast_to(f["free"], clear.shape)[clear] == 1.0)


def test_a_damaged_file_is_made_again(tmp_path):
    path = dataset.level_path(tmp_path, "room", 0)
    path.write_bytes(b"half a file")
    dataset.generate(tmp_path, ["room"], [0], progress=False, steps=40, every=40)
    with np.load(path) as f:
        assert "free" in f.files


def test_test_levels_are_refused(tmp_path):
    with pytest.raises(ValueError, match="test split"):
        dataset.generate(tmp_path, ["room"], [2_000_000], progress=False)


def test_workers_write_the_same_files_as_one_process(tmp_path):
    kw = {"progress": False, "steps": 80, "every": 40}
    one = dataset.generate(tmp_path / "one", ["room", "rocks"], [0, 1], **kw)
    two = dataset.generate(tmp_path / "two", ["room", "rocks"], [0, 1], workers=2, **kw)
    assert [p.name for p in two] == [p.name for p in one] == ["room_0.npz", "rocks_0.npz", "room_1.npz",
                                                              "rocks_1.npz"]  # fmt: skip
    for a, b in zip(one, two, strict=True):
        with np.load(a) as x, np.load(b) as y:
            for key in ("map", "state", "t", "free"):
                np.testing.assert_array_equal(x[key], y[key])
    with pytest.raises(ValueError, match="workers: must be an integer >= 1"):
        dataset.generate(tmp_path, ["room"], [0], workers=0)
