"""Make the pictures the documentation shows: the gallery's figures and the README's demo frame.

The documentation build does not run the examples (27 scripts, many minutes on 2 cores): it shows the
pictures cached in ``docs/gallery/images/``, which this script makes. Rerun it when an example's figure
changes::

    python docs/make_gallery.py                    # every example, then the demo frame
    python docs/make_gallery.py ex2_7_ring ex4_minkowski   # some examples only
    python docs/make_gallery.py --demo-frame       # only docs/_static/demo_frame.png

Each example runs as ``python examples/<name>.py --out <tmp>`` with its own defaults; every PNG it writes
is shrunk to at most ``--width`` pixels and quantized to a palette, then saved as
``docs/gallery/images/<name>__<figure>.png`` (a few MB in all). The demo frame is the last frame of the
GIF of ``digslam demo --steps 300``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"
IMAGES = Path(__file__).resolve().parent / "gallery" / "images"
DEMO_FRAME = Path(__file__).resolve().parent / "_static" / "demo_frame.png"


def example_names() -> list[str]:
    """The example scripts of ``examples/`` (``_common.py`` is their scaffolding, not an example)."""
    return sorted(p.stem for p in EXAMPLES.glob("*.py") if not p.name.startswith("_"))


def shrink(src: Path, dst: Path, width: int, colors: int = 128) -> None:
    """Save ``src`` as ``dst``, at most ``width`` pixels wide, quantized to ``colors`` colours."""
    from PIL import Image

    with Image.open(src) as img:
        img = img.convert("RGB")
        if img.width > width:
            img = img.resize((width, round(img.height * width / img.width)), Image.Resampling.LANCZOS)
        img.quantize(colors=colors, method=Image.Quantize.MEDIANCUT).save(dst, optimize=True)


def run_example(name: str, width: int, timeout: float) -> list[Path]:
    """Run ``examples/<name>.py`` into a temporary folder; shrink and keep its PNGs; return their paths."""
    with tempfile.TemporaryDirectory() as tmp:
        out_args = [tmp] if name == "explore_env" else ["--out", tmp]  # explore_env takes a positional folder
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, str(EXAMPLES / f"{name}.py"), *out_args],
            cwd=REPO,
            capture_output=True,
            text=True,
            timeout=timeout,
            env={**__import__("os").environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy"},
        )
        if proc.returncode != 0:
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["(no output)"]
            print(f"{name}: failed (exit {proc.returncode}): {tail[0]}", file=sys.stderr)
            return []
        for old in IMAGES.glob(f"{name}__*.png"):
            old.unlink()
        kept = []
        for png in sorted(Path(tmp).glob("*.png")):
            dst = IMAGES / f"{name}__{png.stem}.png"
            shrink(png, dst, width)
            kept.append(dst)
        print(f"{name}: {len(kept)} figure(s) in {time.perf_counter() - t0:.0f} s")
        return kept


def demo_frame(steps: int = 300, width: int = 1000) -> Path:
    """``digslam demo --steps <steps>`` into a temporary folder; its GIF's last frame as ``DEMO_FRAME``."""
    import imageio.v3 as iio
    from PIL import Image

    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(
            [sys.executable, "-m", "digslam.agents.cli.main", "demo", "--steps", str(steps), "--out", tmp],
            cwd=tempfile.gettempdir(),  # not the checkout: digslam is a namespace package (see the README)
            check=True,
            env={**__import__("os").environ, "SDL_VIDEODRIVER": "dummy"},
        )
        frames = iio.imread(Path(tmp) / "episode.gif", index=None)
        last = Path(tmp) / "last.png"
        Image.fromarray(frames[-1][..., :3]).save(last)
        DEMO_FRAME.parent.mkdir(parents=True, exist_ok=True)
        shrink(last, DEMO_FRAME, width, colors=256)
    print(f"demo frame: {DEMO_FRAME} ({DEMO_FRAME.stat().st_size // 1024} KB)")
    return DEMO_FRAME


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", help="examples to run (default: all)")
    ap.add_argument("--demo-frame", action="store_true", help="only make docs/_static/demo_frame.png")
    ap.add_argument("--width", type=int, default=900, help="largest width of a gallery picture (default 900)")
    ap.add_argument("--timeout", type=float, default=1200.0, help="seconds per example (default 1200)")
    args = ap.parse_args(argv)
    if args.demo_frame:
        demo_frame()
        return
    unknown = sorted(set(args.names) - set(example_names()))
    if unknown:
        ap.error(f"no example named {', '.join(unknown)}; the examples are {', '.join(example_names())}")
    IMAGES.mkdir(parents=True, exist_ok=True)
    failed = [n for n in (args.names or example_names()) if not run_example(n, args.width, args.timeout)]
    if not args.names:
        demo_frame()
    total = sum(p.stat().st_size for p in IMAGES.glob("*.png"))
    print(f"gallery: {len(list(IMAGES.glob('*.png')))} pictures, {total / 1e6:.1f} MB")
    if failed:
        sys.exit(f"no figure from {', '.join(failed)}")


if __name__ == "__main__":
    main()
