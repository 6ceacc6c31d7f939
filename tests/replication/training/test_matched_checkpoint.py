"""A model read at a registered held-out accuracy (`replication.evaluation.matched`): the kept checkpoint
whose tracked (development) loss is nearest the level, evaluated as the unit's model would be."""
import math

import numpy as np
from parity_rows import BY_NAME

from lagbench.replication.evaluation import matched
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.training import scouting
from lagbench.replication.training.protocol import Tracking
from lagbench.replication.training.train import run_training

SPEC = BY_NAME["lnn_scouted"].spec
PLAIN = scouting.scout_protocol(BY_NAME["lnn_scouted"].protocol).replace(steps=9, log_every=2)


def test_nearest_is_nearest_in_log_and_skips_what_is_not_a_loss():
    assert matched.nearest([8.0, 2.0, 0.6, 0.1], 0.5) == 2
    assert matched.nearest([4.0, 1.0, 0.25], 0.5) == 2          # a tie in log: the later checkpoint
    assert matched.nearest([math.nan, None, math.inf, 0.0, 3.0], 0.5) == 4
    assert matched.nearest([math.nan, None], 0.5) is None


def test_at_level_evaluates_the_checkpoint_chosen_by_its_tracked_loss():
    import dataclasses

    out = run_training("jax", SPEC, PLAIN.replace(tracking=Tracking(every=4, keep=True)), 1)
    tracked = {r["step"]: r for r in out.log if "heldout_loss" in r}
    assert list(out.tracked["step"]) == sorted(tracked) == [0, 4, 8]
    losses = [tracked[s]["heldout_loss"] for s in (0, 4, 8)]
    assert losses[0] != losses[2]
    ctx = dataclasses.make_dataclass("C", ["framework", "spec", "log", "tracked", "params", "model"])(
        "jax", SPEC, out.log, out.tracked, out.params, None)
    seen = []

    def evaluate(c):
        seen.append(c)
        return {"heldout_l1": 1.5}
    got = matched.at_level(ctx, losses[0], evaluate)   # the first checkpoint's own loss picks it
    first = {k[2:]: v[0] for k, v in out.tracked.items() if k.startswith("p/")}
    assert all(np.array_equal(seen[0].params[k], first[k]) for k in first)
    q = np.zeros((3, 2)) + 0.3
    np.testing.assert_allclose(seen[0].model.acceleration(q, q, None),
                               adapter("jax", SPEC, first).acceleration(q, q, None))
    assert got == {"matched_heldout_l1": 1.5, "matched_tracked_l1": losses[0], "match_level": losses[0],
                   "matched_samples": tracked[0]["samples"]}
    assert matched.at_level(dataclasses.replace(ctx, tracked=None), 1.0, evaluate) == {}   # nothing kept
