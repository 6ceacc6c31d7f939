"""Every claim's verdict rule, through `replication.claims.verdicts.judge`: a case that reproduces and a case that
fails, on synthetic unit rows whose models all pass their bars; then what judge does with failed units,
missing models, seeds that disagree and frameworks that disagree."""
import pandas as pd
import pytest

from replication.claims import CLAIMS
from replication.claims.verdicts import judge

NULL = 1000.0   # every null predictor's error: every model below is far under its bar


def _metrics(cid, label, good: bool) -> dict:
    """The rule's metrics of one model: the claimed winner wins when ``good``, loses otherwise."""
    win, lose = (1.0, 40.0) if good else (40.0, 1.0)
    if cid in ("dp_loss",):
        return {"heldout_l1": 0.07 if good or label == "lnn" else 7.0}
    if cid == "dp_energy":
        return {"energy_err_final": win if label == "lnn" else lose, "n_diverged": 0}
    if cid == "rel_coords":
        return {"heldout_l1_qddot": lose if label == "hnn_qqdot" else win}
    if cid == "wave_lgn":
        return {"transfer_ratio": 1.2 if good else 10.0, "energy_err_max": 0.01 if good else 0.5}
    if cid == "appendix_b":
        return {"max_abs_err": 1e-15 if good else 1e-6}
    if cid == "init_study":   # samples to leave the plateau, per seed: the winner's all fewer
        return {"samples_to_leave": 1e3 * (win if label == "lnn_init-cranmer2020" else lose)}
    if cid == "activation_study":
        if label == "lnn_act-relu":   # plain ReLU never leaves the plateau, or (bad case) leaves it first
            return {"heldout_l1": 1.0, "samples_to_leave": float("inf") if good else 1e2}
        return {"heldout_l1": win, "samples_to_leave": 1e3 * (win if label == "lnn_act-softplus" else lose)}
    if cid == "delan_table1":
        return {"heldout_l1": win if label.startswith("lnn") else lose}
    if cid == "delan_arm":
        out = {"torque_mse_test": win if label.startswith("delan") else lose, "torque_mse_train": 1.0}
        return out | ({"mass_matrix_min_eig": 0.1 if good else -0.1} if label == "delan" else {})
    if cid == "hnn_energy":
        return {"energy_err_max": win if label.startswith("hnn") else lose, "n_diverged": 0}
    if cid == "precision":
        drift = (1e-9 if label.endswith("f64") else 1e-3) if good else (1e-3 if label.endswith("f64") else 1e-9)
        return {"truth_energy_drift_final": drift, "heldout_l1": 1.0 if good or label.endswith("f32") else 10.0}
    raise AssertionError(f"no synthetic case for {cid}")


def _row(cid, label, seed, metrics, fw="jax", status="ok"):
    bars = {f"null_{b.metric}": NULL for b in CLAIMS[cid].bars if b.metric}
    bar_vals = {b.metric: 1.0 for b in CLAIMS[cid].bars if b.metric}
    jitter = {k: v * (1 + 0.01 * seed) if k != "n_diverged" else v for k, v in metrics.items()}
    return {"claim": cid, "framework": fw, "model": label, "seed": seed, "status": status,
            **bar_vals, **bars, **jitter}


def _units(cid, good, seeds=None, fw="jax"):
    claim = CLAIMS[cid]
    seeds = seeds or (range(8) if claim.pooled else (0, 1, 2))   # a share needs a sample of seeds
    return pd.DataFrame([_row(cid, m, k, _metrics(cid, m, good), fw) for m in claim.labels("quick") for k in seeds])


@pytest.mark.parametrize("cid", list(CLAIMS))
def test_each_rule_reproduces_and_fails(cid):
    good = judge(CLAIMS[cid], _units(cid, True), "quick")
    bad = judge(CLAIMS[cid], _units(cid, False), "quick")
    assert good["verdict"] == "reproduced", good["reason"]
    assert bad["verdict"] == "not reproduced", bad["reason"]


def test_a_failed_model_is_excluded_and_makes_the_claim_inconclusive():
    df = _units("dp_energy", True)
    df.loc[df["model"] == "lnn", "status"] = "failed"
    df["failure"] = None
    df.loc[df["model"] == "lnn", "failure"] = "non_finite_loss"
    v = judge(CLAIMS["dp_energy"], df, "quick")
    assert v["verdict"] == "inconclusive" and "lnn: every unit failed (non_finite_loss)" in v["reason"]
    assert v["failed_units"] == {"jax": 3}


def test_one_failed_seed_is_excluded_and_said():
    df = _units("dp_energy", True)
    df.loc[(df["model"] == "lnn") & (df["seed"] == 2), "status"] = "failed"
    v = judge(CLAIMS["dp_energy"], df, "quick")
    assert v["verdict"] == "partly" and "1 failed unit excluded" in v["reason"]   # seed 2 lacks the lnn


def test_a_model_without_units_is_not_run():
    df = _units("dp_loss", True)
    v = judge(CLAIMS["dp_loss"], df[df["model"] != "baseline"], "quick")
    assert v["verdict"] == "not run" and "missing baseline" in v["reason"]


def test_a_mean_that_one_seed_contradicts_is_only_partly():
    cid = "dp_energy"
    rows = [_row(cid, m, k, {"energy_err_final": x, "n_diverged": 0}) for m in CLAIMS[cid].labels("quick")
            for k, x in enumerate((1.0, 1.1, 1.2) if m == "lnn" else (30.0, 31.0, 0.5))]
    v = judge(CLAIMS[cid], pd.DataFrame(rows), "quick")
    assert v["by_seed"]["jax"]["seed2"] == "not reproduced"
    assert v["verdict"] in ("partly", "inconclusive") and v["verdict"] != "reproduced"


def test_every_seed_agreeing_keeps_reproduced():
    v = judge(CLAIMS["dp_energy"], _units("dp_energy", True), "quick")
    assert v["verdict"] == "reproduced" and "3/3" in v["reason"]


def _paces(cid, paces: dict, n=8):
    """Rows of a pooled claim: model -> its n seeds' samples to leave the plateau (default: never)."""
    return pd.DataFrame([_row(cid, m, k, {"samples_to_leave": paces.get(m, [float("inf")] * n)[k],
                                          "heldout_l1": 1.0})
                         for m in CLAIMS[cid].labels("quick") for k in range(n)])


def test_training_pace_over_seeds_is_a_rank_test_not_each_seed():
    cid, ours, inf = "init_study", "lnn_init-cranmer2020", float("inf")
    fast, slow = [1e4 + i for i in range(8)], [5e4 + i for i in range(8)]
    others = {m: slow for m in CLAIMS[cid].labels("quick") if m != ours}
    v = judge(CLAIMS[cid], _paces(cid, {ours: fast, **others}), "quick")
    assert v["verdict"] == "reproduced" and "8/8 [0.68, 1.00]" in v["reason"], v["reason"]
    # two of eight leaving against none: a small sample decides nothing
    v = judge(CLAIMS[cid], _paces(cid, {ours: [1e4, 1e4] + [inf] * 6}), "quick")
    assert v["verdict"] == "inconclusive" and "no difference significant" in v["reason"], v["reason"]
    # nobody left the plateau: nothing to compare
    v = judge(CLAIMS[cid], _paces(cid, {}), "quick")
    assert v["verdict"] == "inconclusive" and "no seed of any model got there" in v["reason"], v["reason"]
    # another init clearly faster, every run of ours left later (or never)
    v = judge(CLAIMS[cid], _paces(cid, {ours: slow[:4] + [inf] * 4, "lnn_init-kaiming": fast}), "quick")
    assert v["verdict"] == "not reproduced" and "lnn_init-kaiming faster" in v["reason"], v["reason"]


def test_plain_relu_must_never_leave_while_softplus_leaves_first():
    cid, inf = "activation_study", float("inf")
    fast, slow = [1e4 + i for i in range(8)], [5e4 + i for i in range(8)]
    smooth = {m: slow for m in CLAIMS[cid].labels("quick") if m not in ("lnn_act-softplus", "lnn_act-relu")}
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": fast, **smooth}), "quick")
    assert v["verdict"] == "reproduced" and "lnn_act-relu got there in 0/8 [0.00, 0.32]" in v["reason"], v["reason"]
    # one ReLU seed left the plateau (late): it can learn, so half the claim fails
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": fast, **smooth, "lnn_act-relu": [9e4] + [inf] * 7}),
              "quick")
    assert v["verdict"] == "partly" and "it can learn" in v["reason"], v["reason"]
    # nobody left, ReLU included: the ReLU part alone would pass, the pace part keeps it inconclusive
    v = judge(CLAIMS[cid], _paces(cid, {}), "quick")
    assert v["verdict"] == "inconclusive" and "no seed of any model got there" in v["reason"], v["reason"]
    # softplus never leaves while the smooth ones do: the pace part fails, the ReLU part holds
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": [inf] * 8, **{m: fast for m in smooth}}), "quick")
    assert v["verdict"] == "partly" and "faster (p <" in v["reason"], v["reason"]


def test_wilson_interval_matches_reference_values():
    from replication.claims.rules import wilson

    lo, hi = wilson(0, 10)
    assert lo == 0.0 and abs(hi - 0.2775) < 1e-4      # the textbook 0/10 upper bound
    lo, hi = wilson(5, 10)
    assert abs(lo - 0.2366) < 1e-4 and abs(hi - 0.7634) < 1e-4


def test_frameworks_that_disagree_never_reproduce():
    both = pd.concat([_units("dp_loss", True, fw="jax"), _units("dp_loss", False, fw="torch")])
    assert judge(CLAIMS["dp_loss"], both, "quick")["verdict"] == "partly"
    weak = _units("dp_loss", True, fw="torch")
    weak["heldout_l1"] = NULL
    both = pd.concat([_units("dp_loss", True, fw="jax"), weak])
    v = judge(CLAIMS["dp_loss"], both, "quick")
    assert v["verdict"] == "inconclusive" and v["by_framework"] == {"jax": "reproduced", "torch": "inconclusive"}
