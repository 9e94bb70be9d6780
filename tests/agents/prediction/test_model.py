"""The map predictor: shapes, inputs, save/load round trip, determinism on the CPU, one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from digslam.agents.prediction import model  # noqa: E402


def _maps(n=3, m=40, seed=0):
    rng = np.random.default_rng(seed)
    return (rng.random((n, 4, m, m)) < 0.5).astype(np.uint8) * 255


def test_inputs_are_the_map_channels_and_coordinates():
    x = model.inputs(_maps(2, 36))
    assert x.shape == (2, model.N_INPUTS, 36, 36) and x.dtype == np.float32
    assert set(np.unique(x[:, :4])) <= {0.0, 1.0}
    assert np.all(np.diff(x[0, 4, :, 0]) > 0) and np.all(np.diff(x[0, 5, 0, :]) > 0)  # rows, then columns
    assert x[0, 4].min() > -1 and x[0, 4].max() < 1


@pytest.mark.parametrize("m", [36, 40, 64, 81])
def test_any_map_side(m):
    torch.manual_seed(0)
    pred = model.Predictor(model.MapUNet())
    p, var = pred.free(_maps(1, m)[0])
    assert p.shape == var.shape == (m, m) and np.all((0 < p) & (p < 1))
    np.testing.assert_allclose(var, p * (1 - p))


def test_small_enough():
    assert sum(q.numel() for q in model.MapUNet().parameters()) < 2_000_000


def test_save_load_round_trip_and_determinism(tmp_path):
    torch.manual_seed(1)
    net = model.MapUNet()
    path = model.save(net, tmp_path / "p.pt", {"seed": 1})
    back = model.load(path)
    maps = _maps()
    a = model.Predictor(net).logits(maps)
    np.testing.assert_array_equal(a, back.logits(maps))
    np.testing.assert_array_equal(a, back.logits(maps))  # the same twice
    assert back.meta["seed"] == 1 and back.meta["width"] == net.width


def test_missing_or_damaged_files_say_so(tmp_path):
    with pytest.raises(ValueError, match="no map predictor there"):
        model.load(tmp_path / "none.pt")
    (tmp_path / "bad.pt").write_bytes(b"not torch")
    (tmp_path / "bad.json").write_text("{}")
    with pytest.raises(ValueError, match="not a map predictor saved by digslam"):
        model.load(tmp_path / "bad.pt")


def test_predicts_on_one_thread_and_restores_the_callers_count():
    seen = []

    class Probe(torch.nn.Module):
        def forward(self, x):
            seen.append(torch.get_num_threads())
            return x[:, 0]

    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        model.Predictor(Probe()).logits(_maps(1, 36))
        assert seen == [1] and torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)
