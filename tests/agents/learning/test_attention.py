"""The attention policy over candidate goals: a candidate means the same in any slot, masked slots change
nothing, the untrained policy follows the heuristic's ranking, and it saves and loads with MaskablePPO."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("sb3_contrib")
torch = pytest.importorskip("torch")

from gymnasium import spaces  # noqa: E402

from digslam.agents.learning.attention import (  # noqa: E402
    CandidateAttentionExtractor,
    CandidateAttentionPolicy,
    CandidateScorer,
    rank_prior,
)

N, F, G = 6, 5, 3


def _space(n: int = N) -> spaces.Dict:
    return spaces.Dict({"candidates": spaces.Box(-1, 1, (n, F), np.float32), "mask": spaces.MultiBinary(n),
                        "global": spaces.Box(-1, 1, (G,), np.float32)})  # fmt: skip


def _obs(rng: np.random.Generator, valid: int, batch: int = 3) -> dict[str, torch.Tensor]:
    mask = np.zeros((batch, N), np.float32)
    mask[:, :valid] = 1
    return {"candidates": torch.as_tensor(rng.uniform(-1, 1, (batch, N, F)), dtype=torch.float32),
            "mask": torch.as_tensor(mask), "global": torch.as_tensor(rng.uniform(-1, 1, (batch, G)),
                                                                     dtype=torch.float32)}  # fmt: skip


def _logits(
    ext: CandidateAttentionExtractor, head: CandidateScorer, obs: dict[str, torch.Tensor]
) -> torch.Tensor:
    with torch.no_grad():
        return head(ext(obs))


def test_scores_follow_their_candidate_whatever_its_slot() -> None:
    torch.manual_seed(0)
    ext, head = CandidateAttentionExtractor(_space(), d=16, heads=4), CandidateScorer(N, 16, prior=0.0)
    torch.nn.init.normal_(head.score.weight)
    obs = _obs(np.random.default_rng(1), valid=4)
    perm = torch.tensor([2, 0, 3, 1, 4, 5])  # shuffle the valid slots, keep the padding where it is
    shuffled = {**obs, "candidates": obs["candidates"][:, perm]}
    assert torch.allclose(_logits(ext, head, shuffled), _logits(ext, head, obs)[:, perm], atol=1e-5)


def test_masked_slots_do_not_change_the_valid_ones() -> None:
    torch.manual_seed(0)
    ext, head = CandidateAttentionExtractor(_space(), d=16, heads=2), CandidateScorer(N, 16, prior=1.0)
    torch.nn.init.normal_(head.score.weight)
    obs = _obs(np.random.default_rng(2), valid=3)
    other = {**obs, "candidates": obs["candidates"].clone()}
    other["candidates"][:, 3:] = 0.9  # different padding
    assert torch.allclose(_logits(ext, head, obs)[:, :3], _logits(ext, head, other)[:, :3], atol=1e-6)
    none = {**obs, "mask": torch.zeros_like(obs["mask"])}  # no valid slot: still finite
    assert torch.isfinite(_logits(ext, head, none)).all()


def test_bad_spaces_and_sizes_are_one_line_errors() -> None:
    with pytest.raises(ValueError, match="goal-selection"):
        CandidateAttentionExtractor(spaces.Dict({"map": spaces.Box(0, 1, (2, 2))}))
    with pytest.raises(ValueError, match="heads dividing d"):
        CandidateAttentionExtractor(_space(), d=10, heads=4)
    assert rank_prior(4, 2.0).tolist() == [2.0, 1.5, 1.0, 0.5]


def test_untrained_policy_picks_the_heuristics_first_and_round_trips(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import gymnasium as gym
    from sb3_contrib import MaskablePPO

    import digslam.agents.goals
    from digslam.envs.stack import find_wrapper

    env = gym.make("digslam/DigCoverageGoals-v0", max_steps=120, step_cap=20)
    model = MaskablePPO(CandidateAttentionPolicy, env, n_steps=16, batch_size=8, n_epochs=1, seed=0,
                        device="cpu", policy_kwargs={"d": 16, "heads": 4, "heuristic_prior": 5.0})  # fmt: skip
    obs, _ = env.reset(seed=1_000_000)
    mask = find_wrapper(env, digslam.agents.goals.GoalSelectionEnv).action_masks()
    assert int(model.predict(obs, action_masks=mask, deterministic=True)[0]) == 0
    model.learn(16)
    model.save(tmp_path / "m.zip")
    back = MaskablePPO.load(tmp_path / "m.zip", device="cpu")
    assert isinstance(back.policy, CandidateAttentionPolicy) and back.policy.heuristic_prior == 5.0
    ot, _ = model.policy.obs_to_tensor(obs)
    with torch.no_grad():
        a = model.policy.get_distribution(ot, action_masks=mask[None]).distribution.logits
        b = back.policy.get_distribution(ot, action_masks=mask[None]).distribution.logits
    assert torch.equal(a, b)
    env.close()
