"""digslam.agents: coverage-planning baselines, training, evaluation and the command line."""
