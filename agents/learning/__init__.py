"""Learned agents: training, feature extraction and hyper-parameter sweeps (stable-baselines3, Ray Tune).

Lives here: :mod:`.train` (``TrainConfig``, ``train``), :mod:`.extractor` (the map-state feature extractor),
:mod:`.models` (the shipped pretrained model and its env kwargs), :mod:`.wrappers` (discrete turn-or-go
actions, the tube-growth penalty), :mod:`.sweep_config` and :mod:`.sweep`.

May import: :mod:`digslam.envs`, :mod:`digslam.agents.baselines`, :mod:`digslam.agents.evaluation`,
:mod:`digslam.agents.goals` (on use, by name: the goal-level models); torch, stable-baselines3, sb3-contrib,
ray (on use). No argparse: the command line lives in :mod:`digslam.agents.cli`.
"""
