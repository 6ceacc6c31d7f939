"""No claim, part or variant is ever reproduced by a model that learned nothing.

For every claim, each model of its smoke profile is replaced by a null model, evaluated by the claim's
own evaluation routine, for three seeds, and the verdict path (`replication.claims.verdicts.judge`) runs on the
resulting unit records: predicting zero, the untrained initialisation (the real init numbers, through
the PyTorch adapter), and a model whose rollouts diverge. No claim may come out "reproduced" or "partly",
no part that counts "reproduced", no variant "reproduced" or "partly".
Appendix B trains nothing: its null is an Euler-Lagrange routine that returns zero or inf.
A positive control passes with a model that learned and fails with a null, through the same pipeline.
(`test_verdicts.py` puts a null in every slot a claim needs to succeed, one at a time, for every claim.)
"""
import numpy as np
import pytest
from null_models import Diverging, FieldOracle, NoisyOracle, Zero

import lagbench.models.torch.lnn as torch_lnn
from lagbench.models import init_params
from lagbench.replication.claims import CLAIMS
from lagbench.replication.claims.verdicts import frame, judge
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.registry import EVALUATIONS
from lagbench.replication.evaluation.routines import Context, system_of
from lagbench.replication.run.runner import plan

SEEDS = (0, 1, 2)
NULLS = ("zero", "untrained", "diverging")
# nulls that ignore the seed: the evaluation (which draws nothing of its own) gives each seed the same record,
# so it runs once per unit and the record stands for every seed
SEEDLESS = ("zero", "diverging")


def _model(kind, unit, seed):
    spec = unit.spec()
    if kind == "learned":
        return NoisyOracle(spec, system_of(unit.protocol()), seed=seed)
    if kind in ("field", "field_zeroed"):
        return FieldOracle(spec, system_of(unit.protocol()), use_field=kind == "field")
    if kind == "zero":
        return Zero(spec)
    if kind == "diverging":
        return Diverging(spec)
    return adapter("torch", spec, init_params(spec, seed=seed))


def _records(claim, kind, monkeypatch, kinds=None):
    """Unit records of ``claim`` at the smoke profile, every model replaced by the null ``kind`` (or by
    ``kinds[label]``), three seeds each (a `SEEDLESS` null evaluated once)."""
    if claim.evaluate == "exact_lagrangian":
        value = 0.0 if kind != "diverging" else np.inf
        monkeypatch.setattr(torch_lnn, "euler_lagrange", lambda L, q, qdot, form: q * 0 + value)
    out = []
    for unit in plan("smoke", claims=[claim.id], frameworks=("torch",)):
        model_kind = (kinds or {}).get(unit.entry.label, kind)
        ev = None
        for seed in SEEDS:
            if ev is None or model_kind not in SEEDLESS:
                cfg = claim.eval_config.get("smoke", {})
                ctx = Context(claim=claim, entry=unit.entry, framework="torch", spec=unit.spec(), params=None,
                              protocol=unit.protocol(), profile="smoke", cfg=cfg, model=_model(model_kind, unit, seed))
                with np.errstate(all="ignore"):
                    ev = EVALUATIONS[claim.evaluate](ctx)
            out.append({"claim": claim.id, "framework": "torch", "model": unit.entry.label, "seed": seed,
                        "status": "ok", "profile": "smoke", "metrics": ev.metrics, "final_train_loss": None})
    return out


@pytest.mark.parametrize("kind", NULLS)
@pytest.mark.parametrize("cid", list(CLAIMS))
def test_a_null_model_never_reproduces_a_claim(cid, kind, monkeypatch):
    claim = CLAIMS[cid]
    v = judge(claim, frame(_records(claim, kind, monkeypatch)), "smoke")
    assert v["verdict"] not in ("reproduced", "partly"), v["reason"]
    assert v["verdict"] in ("inconclusive", "not reproduced"), v["reason"]
    assert not [p["name"] for p in v["parts"] if not p["check"] and p["verdict"] == "reproduced"], v["reason"]
    assert all(x["verdict"] not in ("reproduced", "partly") for x in v["variants"]), v["variants"]
    if claim.bars:   # a learned claim: the null is caught by its competence bar, before any rule
        assert v["verdict"] == "inconclusive" and "below the competence bar" in v["reason"], v["reason"]


@pytest.mark.parametrize("cid, kinds, expected", [
    # both learned, with the same small error: similar held-out loss
    ("dp_loss", {"lnn": "learned", "baseline": "learned"}, "reproduced"),
    # the LNN learned, DeLaN predicts nothing, and DeLaN's positive control (the pendulum) learned: the LNN
    # is far better on both systems
    ("delan_table1", {"lnn_relativistic": "learned", "lnn_magnetic": "learned", "delan_control": "learned"},
     "reproduced"),
    # the same, but DeLaN fails its control as well: a DeLaN that learns nothing says nothing
    ("delan_table1", {"lnn_relativistic": "learned", "lnn_magnetic": "learned"}, "inconclusive"),
    # the LNN learned, the baseline did not: no comparison
    ("dp_loss", {"lnn": "learned", "baseline": "zero"}, "inconclusive"),
    ("dp_energy", {"lnn": "learned", "baseline": "diverging"}, "inconclusive"),
])
def test_models_that_learned_are_judged_and_a_null_beside_them_is_caught(cid, kinds, expected, monkeypatch):
    """The other side of the null tests: the bars let a model that learned through, so a verdict can
    be reached at all; one null model beside it still makes the claim inconclusive."""
    claim = CLAIMS[cid]
    v = judge(claim, frame(_records(claim, "zero", monkeypatch, kinds)), "smoke")
    assert v["verdict"] == expected, v["reason"]
    if expected == "inconclusive" and cid == "delan_table1":
        assert "positive control did not learn" in v["reason"], v["reason"]
    learned = [m for m, k in kinds.items() if k == "learned"]
    assert all(v["competence"]["torch"][m]["passed"] for m in learned), v["competence"]


@pytest.mark.parametrize("control, passes", [("field", True), ("field_zeroed", False)])
def test_an_hnn_whose_relativistic_input_is_zeroed_fails_its_same_system_control(control, passes, monkeypatch):
    """Claim 3's positive control is the HNN on (q, qdot) on the relativistic particle itself (speeds up to
    0.1 c), through the same recipe and input path: one that reads the field learns it, one whose field input
    is zeroed does not, so a broken input path cannot read as the failure the paper predicts."""
    claim = CLAIMS["rel_coords"]
    v = judge(claim, frame(_records(claim, "zero", monkeypatch, {"hnn_qqdot_slow": control})), "smoke")
    assert v["competence"]["torch"]["hnn_qqdot_slow"]["passed"] is passes, v["competence"]["torch"]["hnn_qqdot_slow"]
    assert v["verdict"] == "inconclusive", v["reason"]
