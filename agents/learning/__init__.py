"""Learned agents: training, feature extraction and hyper-parameter sweeps (stable-baselines3, Ray Tune).

Lives here: :mod:`.train_config` (``TrainConfig``, read from a file plus overrides), :mod:`.train`
(``train``: one run), :mod:`.algos` (the SB3 model of a config, new or resumed), :mod:`.vec_env` (spawn-safe
env factories, vectorized envs, torch thread pinning), :mod:`.checkpoints` (atomic saves, model sidecars,
the latest checkpoint), :mod:`.warm_start` (behaviour cloning of a teacher before PPO), :mod:`.extractor`
(the map-state feature extractor), :mod:`.attention` (the candidate-attention policy of the goal-level
learner), :mod:`.models` (the shipped models, their env kwargs, loading a saved model), :mod:`.wrappers`
(discrete turn-or-go actions, the tube-growth penalty), :mod:`.sweep_config` and :mod:`.sweep` (Ray Tune
sweeps).

May import: :mod:`digslam.observer.core` (the config base), :mod:`digslam.envs`,
:mod:`digslam.agents.baselines`, :mod:`digslam.agents.evaluation`, :mod:`digslam.agents.goals` (the
teachers' names; the goal-level models on use, by name); torch, stable-baselines3, sb3-contrib, ray (on
use). No argparse: the command line lives in :mod:`digslam.agents.cli`.
"""
