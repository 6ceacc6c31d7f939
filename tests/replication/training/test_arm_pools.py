"""The two-link arm's training pools (`replication.training.data.recipe_arm`): a small pool spreads its
samples over several trajectories, and the cache key sees the change."""
import numpy as np

from lagbench.replication.training import data as datamod
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.replication.training.schedules import Constant

ARM = Protocol(data=Data("two_link_arm", n_train=256, n_heldout=512), task="inverse_dynamics", steps=10, batch=32, loss="mse", schedule=Constant(lr=1e-3))


def test_a_small_pool_is_several_trajectories():
    assert [datamod.arm_trajectories(n) for n in (4, 16, 256, 1024, 1600, 2459, 4096)] == [2, 8, 8, 8, 8, 12, 20]
    pool = datamod.recipe_arm(ARM, 256, np.random.default_rng(0))
    assert pool["q"].shape == (256, 2)
    # 8 trajectories of 32 points: the pool's joint angles span far more than one 4-second trajectory's
    one = datamod.recipe_arm(ARM, 200, np.random.default_rng(0))
    assert np.ptp(pool["q"], 0).min() > np.ptp(one["q"], 0).min()


def test_the_training_cache_key_changes_with_the_pool_rule_and_only_for_small_pools():
    assert datamod.targets_version(ARM) == "arm-min-8-trajectories"
    assert datamod.targets_version(ARM.replace(**{"data.n_train": 4096})) == ""
    assert datamod.targets_version(ARM.replace(**{"data.n_train": 1600})) == ""


def test_the_four_joint_arm_is_a_recipe_of_its_own():
    """A protocol whose data recipe names the four-joint arm draws its trajectories: 4 columns, exact torques."""
    four = ARM.replace(**{"data.recipe": "four_joint_arm"})
    assert datamod.recipe_for(four) is datamod.recipe_arm
    pool = datamod.recipe_arm(four, 64, np.random.default_rng(0))
    assert all(pool[k].shape == (64, 4) for k in ("q", "qdot", "extra", "target"))
    assert np.isfinite(pool["target"]).all() and np.ptp(pool["q"], 0).min() > 0
    two = datamod.recipe_arm(ARM, 64, np.random.default_rng(0))
    assert two["q"].shape == (64, 2)
