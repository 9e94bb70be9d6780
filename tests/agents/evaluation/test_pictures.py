"""The demo's pictures: the GIF's size, frame count and legend; the coverage figure's target and end marks."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PIL")
pytest.importorskip("matplotlib")

from PIL import Image  # noqa: E402

from digslam.agents.cli import main as cli
from digslam.agents.evaluation import pictures  # noqa: E402
from digslam.agents.evaluation.evaluate import EvalResult, coverage_figure  # noqa: E402


@pytest.fixture(scope="module")
def demo(tmp_path_factory):  # type: ignore[no-untyped-def]
    out = tmp_path_factory.mktemp("demo")
    assert cli.main(["demo", "--agent", "frontier", "--steps", "20", "--stride", "4", "--out", str(out)]) == 0
    return out


def test_gif_size_frames_and_legend(demo) -> None:  # type: ignore[no-untyped-def]
    im = Image.open(demo / "episode.gif")
    assert im.size == (pictures.MAP_SIZE + pictures.PANEL_WIDTH, pictures.MAP_SIZE)
    assert im.n_frames == 1 + 20 // 4  # the reset frame and every 4th step
    im.seek(im.n_frames - 1)
    rgb = np.asarray(im.convert("RGB"))
    for k, (key, _, _) in enumerate(pictures.LEGEND):  # each swatch of the legend is drawn in its colour
        y = pictures.LEGEND_TOP + k * pictures.LEGEND_ROW + 12
        x = pictures.MAP_SIZE + 12 + 12
        want = {"box": "dark", "echo": "clear"}.get(key, key)
        assert tuple(rgb[y, x]) == pictures.PALETTE[want], key
    assert (rgb[:, pictures.MAP_SIZE + 46 :] == 0).any()  # the legend's text
    red = np.array([0xE4, 0x1A, 0x1C])
    assert not (rgb[:, : pictures.MAP_SIZE] == red).all(axis=-1).any()  # proved-free is not red


def test_palette_reads_right() -> None:
    p = pictures.PALETTE
    assert p["clear"] != p["penumbra"] != p["dark"] and p["clear"][2] > p["clear"][0]  # blue, not red
    assert [name for _, name, _ in pictures.LEGEND] == ["clear", "penumbra", "dark", "obstacles", "echoes",
                                                       "true robot", "pose box"]  # fmt: skip


def test_coverage_figure_one_episode_that_ended_early(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import matplotlib.axes

    titles, plotted = [], []
    monkeypatch.setattr(matplotlib.axes.Axes, "set_title", lambda self, t, **k: titles.append(t))
    orig = matplotlib.axes.Axes.plot

    def plot(self, *a, **k):  # type: ignore[no-untyped-def]
        plotted.append((a, k))
        return orig(self, *a, **k)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", plot)
    c = np.r_[np.linspace(0, 0.82, 31), np.full(20, 0.82)][None]
    res = EvalResult({"a": c, "b": c.copy()}, {"a": c, "b": c.copy()}, {"a": np.zeros(1), "b": np.zeros(1)},
                     {"a": np.ones(1), "b": np.ones(1)}, {"a": np.array([30.0]), "b": np.array([30.0])},
                     "digslam/DigCoverage-v0", 0, 1)  # fmt: skip
    coverage_figure(res, tmp_path / "c.png", target=0.8)
    assert (tmp_path / "c.png").stat().st_size > 0
    assert "1 episode" in titles[0] and "map(s)" not in titles[0]
    lines = [(a, k) for a, k in plotted if a and len(a[0]) > 1 and k.get("label") in ("a", "b")]
    assert all(len(a[0]) == 31 for a, _ in lines)  # drawn to the end, not as a flat line after it
    assert {k["marker"] for _, k in lines} == {"o", "s"} and lines[0][1]["lw"] > lines[1][1]["lw"]
    assert any(k.get("label") == "episode ended" for _, k in plotted)
