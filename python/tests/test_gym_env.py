"""The Gymnasium example (python/examples/soft_pusher_env.py): Gymnasium's own checker,
deterministic resets, and a scripted push that reaches the target."""

import sys
from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

from soft_pusher_env import SoftPusherEnv, scripted_push  # noqa: E402


def test_gymnasiums_checker_passes():
    from gymnasium.utils.env_checker import check_env

    check_env(SoftPusherEnv(), skip_render_check=True)


def test_an_episode_is_the_same_to_the_bit_for_the_same_seed_and_actions():
    env = SoftPusherEnv()
    actions = np.random.default_rng(7).uniform(-1, 1, size=(40, 2)).astype(np.float32)

    def episode(seed):
        observations = [env.reset(seed=seed)[0]]
        observations += [env.step(a)[0] for a in actions]
        return np.array(observations)

    first = episode(3)
    assert np.array_equal(first, episode(3))
    assert not np.array_equal(first[:, 6], episode(4)[:, 6])  # another seed, another target


def test_the_scripted_push_brings_the_box_within_the_goal_tolerance():
    distances = scripted_push(SoftPusherEnv(), seed=0)
    assert distances[-1] < 0.02 < distances[0] and len(distances) < 200
