"""Evaluating agents: episodes, coverage curves, pictures and Ray-parallel evaluation.

Lives here: :mod:`.evaluate` (``evaluate``, ``EvalResult``, coverage figures), :mod:`.metrics` (the
benchmark metrics: T80 / T90 / T95, AUC, path length, paired bootstrap ratios), :mod:`.suite` (the
benchmark suite over every generator's test levels and its leaderboard), :mod:`.pictures` (demo GIFs and
their legend) and :mod:`.ray_eval` (the same evaluation spread over Ray workers).

May import: :mod:`digslam.envs`, :mod:`digslam.agents.baselines`, :mod:`digslam.agents.learning.models`;
matplotlib, imageio, ray (on use).
"""
