"""What several parts of the agents share: the contract of a policy.

Lives here: :mod:`.policy` (``PolicyPredictor``: a policy that predicts, SB3's ``predict`` signature, which
the baselines, the goal agent and stable-baselines3's models all have; ``PolicyFactory``; ``reset_policy``,
the start of an episode for any of them).

May import: nothing of :mod:`digslam`; numpy and gymnasium (types only).
"""

from .policy import PolicyFactory, PolicyPredictor, reset_policy

__all__ = ["PolicyFactory", "PolicyPredictor", "reset_policy"]
