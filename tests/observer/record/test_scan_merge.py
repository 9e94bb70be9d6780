"""The merged readings of a scan (:mod:`digslam.observer.record.scan_merge`) against a plain loop written from
the module's definition: per group, the longest run of beams that read (the first on a tie), its union cone,
free to the smallest lower range and sensed to the largest upper one."""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.record.scan_merge import can_merge, merge_beams

EPS = np.finfo(np.float64).eps


def oracle(alpha, gamma_beam, rng, no_echo, r_max, reading, groups):  # type: ignore[no-untyped-def]  # test oracle
    n = alpha.size
    out_a, out_g = np.empty(groups), np.full(groups, gamma_beam)
    out_r, out_ne = np.empty(groups), np.zeros(groups, bool)
    out_y = np.tile([0.0, np.inf], (groups, 1))
    for g, idx in enumerate(np.array_split(np.arange(n), groups)):
        runs, start = [], None
        for k in list(idx) + [None]:
            if k is not None and reading[k]:
                start = k if start is None else start
            elif start is not None:
                runs.append((start, (k if k is not None else int(idx[-1]) + 1)))
                start = None
        out_r[g] = float(np.max(r_max[idx]))
        out_a[g] = 0.5 * (alpha[idx[0]] + alpha[idx[-1]])
        if not runs:
            continue
        i, j = max(runs, key=lambda r: (r[1] - r[0], -r[0]))
        a_i, a_j = float(alpha[i]), float(alpha[j - 1])
        out_a[g] = 0.5 * (a_i + a_j)
        half = 0.5 * abs(a_j - a_i) + gamma_beam
        out_g[g] = min(math.pi, half - 8 * EPS * (abs(a_i) + abs(a_j) + half))
        if np.all(no_echo[i:j]) and np.all(r_max[i:j] == r_max[i]):
            out_ne[g], out_r[g] = True, float(r_max[i])
            out_y[g] = [out_r[g], np.inf]
        else:
            out_y[g] = [np.min(rng[i:j, 0]), np.max(rng[i:j, 1])]
            out_r[g] = float(np.max(r_max[i:j]))
    return out_a, out_g, out_r, out_y, out_ne


def test_merge_beams_is_its_definition() -> None:
    rs = np.random.default_rng(0)
    for _ in range(1500):
        n = int(rs.integers(1, 60))
        groups = int(rs.integers(1, n + 1))
        alpha = np.sort(rs.uniform(-3, 3, n))
        reading = rs.random(n) < rs.uniform(0.2, 1.0)
        no_echo = (rs.random(n) < 0.4) & reading
        r_max = np.where(rs.random(n) < 0.7, 20.0, rs.uniform(5, 20, n))
        lo = rs.uniform(0, 20, n)
        rng = np.stack([lo, lo + rs.uniform(0, 1, n)], axis=1)
        rng[no_echo] = np.stack([r_max[no_echo], np.full(int(no_echo.sum()), np.inf)], axis=1)
        rng[~reading] = [0.0, np.inf]
        want = oracle(alpha, 0.01, rng, no_echo, r_max, reading, groups)
        got = merge_beams(alpha, 0.01, rng, no_echo, r_max, reading, groups)
        for w, g in zip(want, got, strict=True):
            assert np.array_equal(w, g)


def test_the_merged_cone_lies_inside_the_union_of_its_beams() -> None:
    inc = math.radians(0.5)
    alpha = -math.pi / 2 + np.arange(361) * inc
    rng = np.tile([3.0, 3.1], (361, 1))
    a, g, _, y, ne = merge_beams(alpha, inc / 2, rng, np.zeros(361, bool), np.full(361, 20.0),
                                 np.ones(361, bool), 37)  # fmt: skip
    splits = np.array_split(np.arange(361), 37)
    for k, idx in enumerate(splits):
        assert a[k] - g[k] >= alpha[idx[0]] - inc / 2 and a[k] + g[k] <= alpha[idx[-1]] + inc / 2
        assert a[k] + g[k] > alpha[idx[-1]] + inc / 2 - 1e-12 and y[k].tolist() == [3.0, 3.1] and not ne[k]


def test_only_scans_taken_at_one_instant_with_tiling_beams_merge() -> None:
    assert can_merge(0.01, 0.005, 0.0)
    assert not can_merge(0.01, 0.005, 1e-5)  # beams at different instants: the robot moves between them
    assert not can_merge(0.01, 0.004, 0.0)  # gaps between the beams' cones
