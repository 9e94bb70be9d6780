"""Evaluating agents: episodes, coverage curves, pictures and Ray-parallel evaluation.

Lives here: :mod:`.evaluate` (``evaluate``, ``EvalResult``, coverage figures), :mod:`.metrics` (the
benchmark metrics: T80 / T85 / T90 / T95, AUC, path length, paired bootstrap ratios), :mod:`.levels` (each
generator's target level, fixed on the validation split), :mod:`.suite` (the benchmark suite over every
generator's test levels and its leaderboard), :mod:`.pictures` (demo GIFs), :mod:`.frames` (one GIF frame
and its legend), :mod:`.overlays` (scale bars, the estimated path, the magnified pose box), and the same
evaluation spread over Ray workers: :mod:`.ray_eval` (``evaluate_ray``, ``run_suite_ray``), :mod:`.specs`
(policies as picklable specs), :mod:`.batches` (blocks of episodes, results back in map order) and
:mod:`.ray_pool` (the pool of long-lived actors).

May import: :mod:`digslam.observer.core` and :mod:`digslam.observer.thick` (the cell codes),
:mod:`digslam.envs` (with its ``sim``, ``explore`` and ``dig_coverage`` folders),
:mod:`digslam.agents.common` (the policy contract), :mod:`digslam.agents.baselines`,
:mod:`digslam.agents.learning`; matplotlib, imageio, ray (on use).
"""
