"""The demo's pictures: the GIF's size, frame count and legend; the pose box drawn where it can be seen, the
scale bars, the estimated path and the echoes' own colour; the coverage figure's target, end marks and end."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PIL")
pytest.importorskip("matplotlib")

from PIL import Image  # noqa: E402

from digslam.agents.cli import main as cli
from digslam.agents.evaluation import frames, pictures  # noqa: E402
from digslam.agents.evaluation.evaluate import EvalResult, coverage_figure  # noqa: E402
from digslam.envs.stack import observer_of  # noqa: E402


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
        y, x = pictures.LEGEND_TOP + k * pictures.LEGEND_ROW, pictures.MAP_SIZE + 12
        swatch = {tuple(int(v) for v in c) for c in rgb[y : y + 25, x : x + 25].reshape(-1, 3)}
        assert pictures.PALETTE[key] in swatch, key
    assert (rgb[:, pictures.MAP_SIZE + 46 :] == 0).any()  # the legend's text
    red = np.array([0xE4, 0x1A, 0x1C])
    assert not (rgb[:, : pictures.MAP_SIZE] == red).all(axis=-1).any()  # proved-free is not red


def test_palette_reads_right() -> None:
    p = pictures.PALETTE
    assert p["clear"] != p["penumbra"] != p["dark"] and p["clear"][2] > p["clear"][0]  # blue, not red
    assert [name for _, name, _ in pictures.LEGEND] == ["clear", "penumbra", "dark", "obstacles", "echoes",
                                                       "estimated path", "pose box", "true robot"]  # fmt: skip
    far = lambda a, b: float(np.linalg.norm(np.subtract(p[a], p[b]))) > 100  # noqa: E731
    assert far("echo", "penumbra") and far("echo", "clear") and far("echo", "obstacle")  # an echo of its own
    assert len(set(p.values())) == len(p) - 1 and p["box"] == p["background"]  # one colour per meaning


@pytest.fixture(scope="module")
def first_frame():  # type: ignore[no-untyped-def]
    """The reset frame of a small map (the pose box is then a point) and the drawer that drew it."""
    from digslam.agents.evaluation.evaluate import make_env

    env = make_env("digslam/DigCoverage-v0", 10, {"map_size": 36})
    _, info = env.reset(seed=0)
    drawer = pictures.FrameDrawer(observer_of(env), "t", info.get("target"), 10)
    img = drawer.frame(info, 0)
    img.putpalette(frames.flat_palette())  # as write_gif does
    rgb = np.asarray(img.convert("RGB"))
    env.close()
    return drawer, info, rgb


def _extent(mask: np.ndarray) -> tuple[int, int]:
    ys, xs = np.nonzero(mask)
    return int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)


def test_tiny_pose_box_is_outlined_at_least_min_px(first_frame) -> None:  # type: ignore[no-untyped-def]
    from digslam.agents.evaluation import overlays

    drawer, info, rgb = first_frame
    box = np.asarray(info["pose_box"])
    assert float(np.max(box[1] - box[0])) * drawer.px < 1  # narrower than a pixel on the map
    cx, cy = (int(round(v)) for v in drawer._pix(*(0.5 * (box[0] + box[1]))))
    r = overlays.MIN_BOX_PX
    near = rgb[cy - r : cy + r, cx - r : cx + r]
    white = (near == pictures.PALETTE["box"]).all(axis=-1)
    assert min(_extent(white)) >= overlays.MIN_BOX_PX  # the outline, white edged with ink, on the map
    x0, y0 = pictures.MAP_SIZE + pictures.LEGEND_WIDTH + pictures.INSET_AT[0], pictures.INSET_AT[1]
    inset = rgb[y0 : y0 + pictures.INSET_SIZE, x0 : x0 + pictures.INSET_SIZE]
    white = (inset == pictures.PALETTE["box"]).all(axis=-1)
    w, h = _extent(white)
    assert overlays.MIN_INSET_BOX_PX <= min(w, h) and max(w, h) < pictures.INSET_SIZE // 2  # centred, small
    n = pictures.INSET_SIZE
    centre = inset[n // 2 - 3 : n // 2 + 4, n // 2 - 3 : n // 2 + 4]
    assert (centre == pictures.PALETTE["robot"]).all(-1).any()  # the true position, inside the box


def _longest_ink_run(region: np.ndarray) -> int:
    ink = (region == pictures.PALETTE["ink"]).all(axis=-1)
    best = 0
    for row in ink:
        edges = np.diff(np.r_[0, row.astype(np.int8), 0])
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        best = max(best, int((ends - starts).max(initial=0)))
    return best


def test_scale_bars_are_drawn_with_round_lengths(first_frame) -> None:  # type: ignore[no-untyped-def]
    from digslam.agents.evaluation import overlays

    drawer, _, rgb = first_frame
    m = overlays.round_length(pictures.MAP_SIZE / 8 / drawer.px)
    assert m in (1.0, 2.0, 5.0, 10.0) and abs(m * drawer.px - pictures.MAP_SIZE / 8) < pictures.MAP_SIZE / 8
    corner = rgb[pictures.MAP_SIZE - 30 :, :160]  # bottom-left corner of the map: the bar and its paper box
    assert abs(_longest_ink_run(corner[10:-8]) - m * drawer.px) <= 2
    assert (corner == pictures.PALETTE["background"]).all(axis=-1).sum() > 200
    x0, y0 = pictures.MAP_SIZE + pictures.LEGEND_WIDTH + pictures.INSET_AT[0], pictures.INSET_AT[1]
    below = rgb[y0 + pictures.INSET_SIZE + 12 : y0 + pictures.INSET_SIZE + 28, x0 : x0 + pictures.INSET_SIZE]
    k = pictures.INSET_SIZE / overlays.inset_window(0.0)  # the inset's pixels per metre
    assert abs(_longest_ink_run(below) - overlays.round_length(pictures.INSET_SIZE / 2.5 / k) * k) <= 2
    assert overlays.metres_label(2.0) == "2 m" and overlays.metres_label(0.05) == "5 cm"
    assert [overlays.round_length(x) for x in (0.7, 1.0, 3.0, 9.99)] == [0.5, 1.0, 2.0, 5.0]
    assert overlays.inset_window(0.0) == overlays.INSET_MIN_M and overlays.inset_window(0.06) == 0.2


def test_echoes_and_estimated_path(first_frame) -> None:  # type: ignore[no-untyped-def]
    from digslam.agents.evaluation import overlays

    drawer, info, rgb = first_frame
    on_map = {tuple(int(v) for v in c) for c in np.unique(rgb[:, : pictures.MAP_SIZE].reshape(-1, 3), axis=0)}
    assert not info["record"].no_echo.all() and pictures.PALETTE["echo"] in on_map
    t = overlays.Trail()
    for step in range(5):
        t.add(step, np.array([[step, 0.0], [step + 0.2, 0.2]]))
    t.add(4, np.array([[9.0, 9.0], [9.0, 9.0]]))  # once a step
    assert t.steps == [0, 1, 2, 3, 4] and t.xy[-1] == (4.1, 0.1)  # the pose box centres, not the truth
    drawer.observe({"pose_box": np.full((2, 2), np.nan), "consistent": False}, 1)
    assert drawer.trail.xy == []  # claims withdrawn: the path too


def test_lettering_writes_what_pil_writes() -> None:
    from PIL import ImageDraw

    from digslam.agents.evaluation import overlays

    write = overlays.Lettering()
    for size in (12, 16):
        font = frames._font(size)
        for text in ("pose box 0.046 m wide", "jygq W", " "):
            a, b = Image.new("P", (300, 40), 0), Image.new("P", (300, 40), 0)
            ImageDraw.Draw(a).text((7, 5), text, fill=3, font=font)
            write(b, (7, 5), text, font, 3)
            write(b, (7, 5), text, font, 3)  # the cached mask
            assert np.array_equal(np.asarray(a), np.asarray(b)), text


def test_demo_curves_and_coverage_axis_end_at_the_last_step(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import matplotlib.figure

    class Forward:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):  # type: ignore[no-untyped-def]
            return np.array([1.0, 0.0], np.float32), state

    res = pictures.demo_episode(Forward(), path=tmp_path / "e.gif", steps=80, stride=40,
                                env_kwargs={"map_size": 36, "target": 0.3})  # fmt: skip
    n = int(res.lengths["agent"][0])
    assert n < 80 and res.n_steps == n and res.curves["agent"].shape == (1, n + 1)  # ended early
    xlims, save = [], matplotlib.figure.Figure.savefig

    def savefig(self, *a, **k):  # type: ignore[no-untyped-def]
        xlims.append(self.axes[0].get_xlim())
        return save(self, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    coverage_figure(res, tmp_path / "c.png", target=0.3)
    assert xlims == [(0.0, float(n))]


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
