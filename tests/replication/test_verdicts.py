"""Verdicts judge the seed spread: the claim's rule on the seed means, then on every seed alone."""
import pandas as pd

from replication.claims import get
from replication.verdicts import claim_verdict


def _units(values: dict) -> pd.DataFrame:
    """values {(model, seed): metric} -> the summary/units.csv rows of init_study in JAX."""
    return pd.DataFrame([{"claim": "init_study", "framework": "jax", "model": m, "seed": k, "status": "ok",
                          "heldout_l1": v} for (m, k), v in values.items()])


def test_a_mean_that_one_seed_contradicts_is_only_partly():
    claim = get("init_study")
    ours, theirs = "lnn_init-cranmer2020", "lnn_init-xavier"
    v = claim_verdict(claim, _units({(ours, 0): 1.0, (ours, 1): 5.0, (theirs, 0): 4.0, (theirs, 1): 3.5}))
    assert v["by_seed"]["jax"] == {"seed0": "reproduced", "seed1": "not reproduced"}  # mean 3 < 3.75
    assert v["verdict"] == "partly" and "1/2" in v["reason"]


def test_every_seed_agreeing_keeps_reproduced():
    claim = get("init_study")
    ours, theirs = "lnn_init-cranmer2020", "lnn_init-xavier"
    v = claim_verdict(claim, _units({(ours, 0): 1.0, (ours, 1): 2.0, (theirs, 0): 4.0, (theirs, 1): 3.5}))
    assert v["verdict"] == "reproduced" and "2/2" in v["reason"]
