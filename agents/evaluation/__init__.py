"""Evaluating agents: episodes, coverage curves, pictures and Ray-parallel evaluation.

Lives here: :mod:`.evaluate` (``evaluate``, ``EvalResult``, coverage figures), :mod:`.metrics` (the
benchmark metrics: T80 / T85 / T90 / T95, AUC, path length, paired bootstrap ratios), :mod:`.levels` (each
generator's target level, fixed on the validation split), :mod:`.suite` (the benchmark suite over every
generator's test levels and its leaderboard), :mod:`.pictures` (demo GIFs), :mod:`.frames` (one GIF frame
and its legend), :mod:`.overlays` (scale bars, the estimated path, the magnified pose box) and
:mod:`.ray_eval` (the same evaluation spread over Ray workers).

May import: :mod:`digslam.envs`, :mod:`digslam.agents.baselines`, :mod:`digslam.agents.learning.models`;
matplotlib, imageio, ray (on use).
"""
