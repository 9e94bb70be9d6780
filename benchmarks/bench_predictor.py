"""The map predictor's quality on held-out validation levels, against the two guesses it must beat.

Takes snapshots of the first ``--levels`` validation levels of every generator (the episodes of
:mod:`digslam.agents.prediction.dataset`, cached under ``--data``), predicts them with the shipped map
predictor (``agents/data/map_predictor.pt``, or ``--model``) and scores it on the pixels that are dark or
penumbra in the input (:mod:`digslam.agents.prediction.quality`): accuracy, IoU of the free pixels and the
calibration error (ECE), per generator and over all, beside ``base_rate`` (every open pixel free at the
training set's free share, from the predictor's sidecar) and ``dilate`` (free within 3 pixels of the clear
area). "All" is the procedural generators (:data:`~digslam.envs.sim.generators.PROCEDURAL`); the floorplan levels (windows of the validation plans, as the benchmark's,
:data:`digslam.agents.evaluation.suite.GENERATORS`) are scored apart: the shipped predictor saw windows of
the six training plans only (``agents/configs/map_predictor_buildings.toml``), never the validation plans'.
Ends with ``<metric>_<generator>=`` lines for the predictor, ``base_rate_iou=``, ``dilate_iou=``,
``base_rate_accuracy=``, ``dilate_accuracy=``, ``predictor_accuracy=``, ``predictor_ece=`` and
``predictor_iou_dark=`` (over the procedural generators), and ``predictor_iou_floorplan=`` (the floorplan
windows' open pixels).

Usage: ``python benchmarks/bench_predictor.py [--quick] [--levels 24] [--model PATH] [--data DIR]
[--generators G ...]``; ``--quick``: one level per generator, 300-step episodes (a minute); ``--generators
floorplan``: the floorplan windows alone (``predictor_iou_floorplan=`` and its table rows).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from digslam.agents.prediction import dataset, quality
from digslam.agents.prediction.model import SHIPPED, load
from digslam.envs.sim.generators import BENCHMARK, PROCEDURAL
from digslam.envs.splits import seeds

#: The generators scored: the benchmark's, those the predictor trains on (:data:`PROCEDURAL`) and the rest.
GENERATORS = list(BENCHMARK)
#: The generators of the ``all`` rows and of ``predictor_iou_dark`` (the shipped predictor's training set).
TRAINED = [g for g in GENERATORS if g in PROCEDURAL]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, default=24, help="validation levels per generator (default 24)")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 1 level per generator, 300 steps")
    ap.add_argument("--model", type=Path, default=SHIPPED, help="the map predictor (.pt with its .json)")
    ap.add_argument("--data", type=Path, default=Path("out/predictor_data"), help="snapshot cache folder")
    ap.add_argument("--generators", nargs="+", default=GENERATORS, metavar="G",
                    help=f"score these generators only (default: {' '.join(GENERATORS)})")  # fmt: skip
    args = ap.parse_args()
    unknown = [g for g in args.generators if g not in GENERATORS]
    if unknown:
        ap.error(f"--generators: unknown {unknown}; known: {GENERATORS}")
    try:
        pred = load(args.model)
    except (ImportError, ValueError) as exc:
        ap.error(str(exc).splitlines()[0])
    levels, steps = (1, 300) if args.quick else (args.levels, 2000)
    root = args.data / ("quick" if args.quick else "full")
    t0 = time.perf_counter()
    paths = dataset.generate(root, args.generators, seeds("validation", levels), steps=steps, every=60)
    data = dataset.load(paths)
    p = 1.0 / (1.0 + np.exp(-np.concatenate([pred.logits(data["map"][i : i + 256])
                                              for i in range(0, len(data["map"]), 256)])))  # fmt: skip
    rate = float(pred.meta.get("base_rate", quality.base_rate(data["map"], data["free"])))
    gens = np.asarray(data["generator"])
    seen = np.isin(gens, TRAINED)
    rep = (
        quality.report(p[seen], data["map"][seen], data["free"][seen], gens[seen], rate) if seen.any() else {}
    )
    for g in GENERATORS:
        if g not in TRAINED and (gens == g).any():
            part = gens == g
            rep[g] = quality.report(p[part], data["map"][part], data["free"][part], gens[part], rate)[g]
    print(f"{len(data['map'])} snapshots of {len(paths)} validation levels; {time.perf_counter() - t0:.0f} s")
    print("| generator | guess | accuracy | IoU | ECE | open pixels |\n|---|---|---|---|---|---|")
    for g, rows in rep.items():
        for name, s in rows.items():
            print(
                f"| {g} | {name} | {s['accuracy']:.3f} | {s['iou']:.3f} | {s['ece']:.3f} | {s['pixels']:.0f} |"
            )
    for g in [g for g in GENERATORS if g in rep]:
        s = rep[g]["predictor"]
        print(f"iou_{g}={s['iou']:.4f}\naccuracy_{g}={s['accuracy']:.4f}\nece_{g}={s['ece']:.4f}")
    if "all" in rep:
        for name in ("base_rate", "dilate"):
            print(
                f"{name}_iou={rep['all'][name]['iou']:.4f}\n{name}_accuracy={rep['all'][name]['accuracy']:.4f}"
            )
        print(f"predictor_accuracy={rep['all']['predictor']['accuracy']:.4f}")
        print(f"predictor_ece={rep['all']['predictor']['ece']:.4f}")
        print(f"predictor_iou_dark={rep['all']['predictor']['iou']:.4f}")
    if "floorplan" in rep:
        print(f"predictor_iou_floorplan={rep['floorplan']['predictor']['iou']:.4f} (validation plans' windows, "
              "never trained on)")  # fmt: skip


if __name__ == "__main__":
    main()
