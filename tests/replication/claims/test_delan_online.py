"""Claim 13 (`delan_online`): nothing trained offline, both models on the online learner's one fixed setting (so
tuned alike), the study's loop settings in every profile, and a verdict that never calls a model sooner when
no seed of either reached the threshold."""
import math

import pandas as pd

from lagbench.replication.claims import PROFILES, get, registration, tuned
from lagbench.replication.claims.resolved import tuning
from lagbench.replication.claims.verdicts import judge
from lagbench.replication.studies import online as O
from lagbench.replication.studies.online_learner import claim_model

CLAIM = get("delan_online")


def _rows(t_reach: dict, final: float = 0.01, null: float = 1.0):
    return pd.DataFrame([{"claim": CLAIM.id, "framework": "jax", "model": m, "seed": 1000 + k, "status": "ok",
                          "t_reach_s": t, "tail_mse": final, "null_tail_mse": null}
                         for m, ts in t_reach.items() for k, t in enumerate(ts)])


def test_both_models_learn_online_with_the_learners_fixed_settings_and_are_tuned_alike():
    assert [m.label for m in CLAIM.models] == ["delan", "ff"] and not any(m.train for m in CLAIM.models)
    for profile in PROFILES:
        e, p = CLAIM.evaluation_config(profile), CLAIM.protocol(profile)
        assert (e["every"], e["steps"], e["batch"], e["threshold"]) == (O.EVERY, O.STEPS, O.BATCH, O.THRESHOLD)
        assert e["sustain"] == O.SUSTAIN == 5.0
        assert p == claim_model("delan")[1].replace(batch=O.BATCH, steps=round(e["seconds"] * O.C.RATE))
        t = tuning(CLAIM, profile)   # searched like trainings (by hand until a search is adopted)
        assert set(t) == {"delan", "ff"} and tuned.equal(t)
    assert CLAIM.evaluation_config("quick")["seconds"] == 30.0 and CLAIM.evaluation_config("paper")["seconds"] == 60.0
    v = judge(CLAIM, _rows({"delan": (1.0, 1.5, 2.0), "ff": (4.0, 5.0, 6.0)}), "quick",
              registration.registrations(), tuned.records())
    assert v["preregistration"]["equal_tuning"] and v["verdict"] == "reproduced", v["reason"]


def test_neither_model_reaching_the_threshold_is_inconclusive_never_reproduced():
    inf = (math.inf,) * 3
    v = judge(CLAIM, _rows({"delan": inf, "ff": inf}), "quick")
    assert v["verdict"] == "inconclusive" and "neither is sooner" in v["reason"], v["reason"]
    v = judge(CLAIM, _rows({"delan": inf, "ff": (2.0, 3.0, 4.0)}), "quick")
    assert v["verdict"] == "not reproduced", v["reason"]


def test_a_model_that_did_not_learn_is_below_the_bar():
    v = judge(CLAIM, _rows({"delan": (1.0,) * 3, "ff": (4.0,) * 3}, final=0.8), "quick")
    assert v["verdict"] == "inconclusive" and "below the competence bar" in v["reason"], v["reason"]
