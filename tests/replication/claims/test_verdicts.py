"""Every claim's parts, through `replication.claims.verdicts.judge`: a case that reproduces and a case that
fails, on synthetic unit rows whose models all pass their bars; then what judge does with failed units,
missing models, seeds that disagree, frameworks that disagree, parts that differ, and variants."""
import pandas as pd
import pytest

from lagbench.replication.claims import CLAIMS
from lagbench.replication.claims.verdicts import judge

NULL = 1000.0   # every null predictor's error: every model below is far under its bar


def _metrics(cid, label, good: bool) -> dict:
    """The rule's metrics of one model: the claimed winner wins when ``good``, loses otherwise."""
    win, lose = (1.0, 40.0) if good else (40.0, 1.0)
    if cid in ("dp_loss",):
        return {"heldout_l1": 0.07 if good or label == "lnn" else 7.0}
    if cid == "dp_energy":
        return {"energy_err_final_median": win if label == "lnn" else lose, "n_diverged": 0,
                "matched_energy_err_final_median": win if label == "lnn" else lose, "matched_heldout_l1": 0.5}
    if cid == "rel_coords":
        return {"heldout_l1_qddot": lose if label in ("hnn_qqdot", "hnn_qqdot_gamma") else win}
    if cid == "wave_lgn":
        return {"transfer_ratio": 1.2 if good else 10.0, "energy_err_max": 0.01 if good else 0.5,
                "rollout_gmean_err": 0.1 if good else 0.9, "null_rollout_gmean_err": 1.0}
    if cid == "appendix_b":
        return {"max_abs_err": 1e-15 if good else 1e-6}
    if cid == "init_study":   # samples to leave the plateau, per seed: the winner's all fewer
        return {"heldout_l1": 1.0, "samples_to_leave": 1e3 * (win if label == "lnn_init-cranmer2020" else lose)}
    if cid == "activation_study":
        if label == "lnn_act-relu":   # plain ReLU never leaves the plateau, or (bad case) leaves it first
            return {"heldout_l1": 1.0, "samples_to_leave": float("inf") if good else 1e2}
        return {"heldout_l1": win, "samples_to_leave": 1e3 * (win if label == "lnn_act-softplus" else lose)}
    if cid == "delan_table1":
        return {"heldout_l1": win if label.startswith("lnn") or label == "delan_control" else lose}
    if cid == "delan_arm":
        out = {"torque_mse_test": win if label.startswith("delan") else lose, "torque_mse_train": 1.0}
        return out | ({"mass_matrix_min_eig": 0.1 if good else -0.1} if label == "delan" else {})
    if cid == "delan_tracking":
        return {"tracking_mse_test": win if label == "delan" else lose,
                "tracking_mse_train_x2": win if label == "delan" else lose}
    if cid == "delan_online":   # seconds of learning online to reach 0.1 x PD alone's tracking error
        return {"t_reach_s": win if label == "delan" else lose}
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


def _slots(claim):
    """The models a claim needs to succeed: each one a counted part reads or controls and a bar covers."""
    barred = {m for b in claim.bars for m in b.models}
    return sorted({m for p in claim.parts if not p.check for m in (*p.reads, *p.controls)} & barred
                  & set(claim.labels("quick")))


@pytest.mark.parametrize("cid", list(CLAIMS))
def test_a_null_in_any_slot_the_claim_needs_to_succeed_stops_it(cid):
    """From the case that reproduces, each needed model in turn put at its null predictor's error (and then
    diverged): no claim, part or variant comes out reproduced or partly through that model."""
    claim = CLAIMS[cid]
    assert judge(claim, _units(cid, True), "quick")["verdict"] == "reproduced"
    for slot in _slots(claim):
        for value in (NULL, float("inf")):
            df = _units(cid, True)
            for b in claim.bars:
                if b.metric and slot in b.models:
                    df.loc[df["model"] == slot, b.metric] = value
            v = judge(claim, df, "quick")
            assert v["verdict"] not in ("reproduced", "partly"), (slot, v["reason"])
            assert not [p["name"] for p in v["parts"] if not p["check"] and p["verdict"] == "reproduced"
                        and slot in (*p["reads"], *p["controls"])], (slot, v["reason"])


def test_every_model_a_part_reads_carries_a_bar_or_a_control():
    """A model a counted part reads either has a competence bar, or the part has a positive control that
    does (the failing side of a "fails" part); in a pooled pace study the reference model has its bar."""
    for claim in CLAIMS.values():
        barred = {m for b in claim.bars for m in b.models}
        for part in claim.parts:
            if part.check or claim.kind == "check":
                continue
            bare = set(part.reads) - barred
            covered = bool(set(part.controls) & barred) or (claim.pooled and set(part.reads) & barred)
            assert not bare or covered, (claim.id, part.name, sorted(bare))


def test_a_failed_model_is_excluded_and_makes_the_claim_inconclusive():
    df = _units("dp_energy", True)
    df.loc[df["model"] == "lnn", "status"] = "failed"
    df["failure"] = None
    df.loc[df["model"] == "lnn", "failure"] = "non_finite_loss"
    v = judge(CLAIMS["dp_energy"], df, "quick")
    assert v["verdict"] == "inconclusive" and "lnn: 3 of 3 seeds failed (non_finite_loss)" in v["reason"]
    assert v["failed_units"] == {"jax": 3}


def test_one_failed_seed_is_a_failing_seed_never_dropped():
    df = _units("dp_energy", True)
    df.loc[(df["model"] == "lnn") & (df["seed"] == 2), "status"] = "failed"
    v = judge(CLAIMS["dp_energy"], df, "quick")
    assert v["verdict"] == "inconclusive" and "lnn: 1 of 3 seeds failed" in v["reason"], v["reason"]
    seeds = v["competence"]["jax"]["lnn"]["per_seed"]
    assert [x["passed"] for x in seeds] == [True, True, False] and [x["seed"] for x in seeds] == [0, 1, 2]


@pytest.mark.parametrize("cid, model, metric", [("dp_loss", "lnn", "heldout_l1"),
                                                ("dp_energy", "lnn", "energy_err_final_median"),
                                                ("delan_arm", "delan", "torque_mse_test")])
def test_a_favoured_model_with_one_nan_seed_of_five_is_never_reproduced(cid, model, metric):
    seeds = (0, 1, 2, 3, 4)
    assert judge(CLAIMS[cid], _units(cid, True, seeds), "quick")["verdict"] == "reproduced"
    for col in (metric, CLAIMS[cid].bars[0].metric):
        df = _units(cid, True, seeds)
        df.loc[(df["model"] == model) & (df["seed"] == 3), col] = float("nan")
        v = judge(CLAIMS[cid], df, "quick")
        assert v["verdict"] not in ("reproduced", "partly"), (col, v["reason"])


def test_one_diverged_baseline_rollout_cannot_decide_claim_2():
    """Both models equally good on 39 of 40 initial conditions, the baseline diverged on the 40th: the median
    over initial conditions each seed is read by is unmoved, so the LNN is not "far better"."""
    import numpy as np

    from lagbench.replication.evaluation.metrics import energy_errors

    rows = []
    for k in range(5):
        rng = np.random.default_rng(k)
        e_true = np.zeros((40, 10))
        drift = {m: e_true + rng.uniform(0.01, 0.02, (40, 1)) * np.linspace(0, 1, 10) for m in ("lnn", "baseline")}
        drift["baseline"][7, 5:] = np.inf
        for m, e in drift.items():
            met = energy_errors(e, e_true, 29.4)
            rows.append(_row("dp_energy", m, k, {**met, "n_diverged": 0,
                                                  "matched_energy_err_final_median": met["energy_err_final_median"],
                                                  "matched_heldout_l1": 0.5}))
    df = pd.DataFrame(rows)
    assert np.isinf(df[df["model"] == "baseline"]["energy_err_final"]).all()   # the mean the original read
    v = judge(CLAIMS["dp_energy"], df, "quick")
    assert v["parts"][0]["verdict"] == "not reproduced", v["reason"]


def test_a_model_without_units_is_not_run():
    df = _units("dp_loss", True)
    v = judge(CLAIMS["dp_loss"], df[df["model"] != "baseline"], "quick")
    assert v["verdict"] == "not run" and "missing baseline" in v["reason"]


def test_a_seed_that_contradicts_the_others_makes_the_part_inconclusive():
    cid = "dp_energy"
    rows = [_row(cid, m, k, {"energy_err_final_median": x, "n_diverged": 0}) for m in CLAIMS[cid].labels("quick")
            for k, x in enumerate((1.0, 1.1, 1.2) if m == "lnn" else (30.0, 31.0, 0.5))]
    v = judge(CLAIMS[cid], pd.DataFrame(rows), "quick")
    assert v["verdict"] == "inconclusive" and v["parts"][0]["verdict"] == "inconclusive", v["reason"]
    iv = v["parts"][0]["interval"]["jax"]
    assert iv["lo"] < 1 / 3 < iv["hi"]


def test_every_seed_agreeing_keeps_reproduced_with_its_interval_and_sensitivity():
    v = judge(CLAIMS["dp_energy"], _units("dp_energy", True), "quick")
    part = v["parts"][0]
    assert v["verdict"] == "reproduced" and part["verdict"] == "reproduced"
    assert part["interval"]["jax"]["hi"] < 1 / 3 and set(part["sensitivity"]["jax"]) == {"factor 1.5", "factor 6"}


def test_partly_means_named_parts_reproduced_and_others_not():
    cid = "hnn_energy"
    df = _units(cid, True)
    flip = df["model"].isin(["hnn_pendulum", "baseline_pendulum"])
    df.loc[flip & (df["model"] == "hnn_pendulum"), "energy_err_max"] = 40.0
    df.loc[flip & (df["model"] == "baseline_pendulum"), "energy_err_max"] = 1.0
    v = judge(CLAIMS[cid], df, "quick")
    assert v["verdict"] == "partly", v["reason"]
    assert v["reason"].startswith("reproduced: spring; not reproduced: pendulum"), v["reason"]
    # one part undecided: the claim is undecided, never partly
    df.loc[df["model"] == "hnn_pendulum", "energy_err_max"] = [0.1, 0.2, 0.5]
    v = judge(CLAIMS[cid], df, "quick")
    assert v["verdict"] == "inconclusive" and "undecided: pendulum" in v["reason"], v["reason"]


def test_a_sanity_check_never_counts():
    """delan_arm's positive-definite mass matrix holds for any DeLaN: a failing check leaves the verdict."""
    df = _units("delan_arm", True)
    df.loc[df["model"] == "delan", "mass_matrix_min_eig"] = -0.1
    v = judge(CLAIMS["delan_arm"], df, "quick")
    check = next(p for p in v["parts"] if p["check"])
    assert check["verdict"] == "not reproduced" and v["verdict"] == "reproduced", v["reason"]


def test_a_variant_has_its_own_line_and_never_decides():
    """claim 3 with the paper's LNN (qdot alone) on its plateau and the gamma variant learned."""
    cid = "rel_coords"
    df = _units(cid, True)
    df.loc[df["model"] == "lnn", "heldout_l1_qddot"] = NULL   # at the null: below its bar
    v = judge(CLAIMS[cid], df, "quick")
    assert v["verdict"] == "inconclusive" and "inconclusive: budget" in v["reason"], v["reason"]
    assert "of the original's 6.14e+07 samples" in v["reason"]
    (var,) = v["variants"]
    assert var["verdict"] == "reproduced" and "gamma" in var["departure"], var
    # without the variant's units, its line says so
    v = judge(CLAIMS[cid], df[~df["model"].isin(["lnn_gamma", "hnn_qqdot_gamma"])], "quick")
    assert v["variants"][0]["verdict"] == "not run"


def _lnn_on_plateau(seeds, width="500x500x500x500", samples=1e8, control=True):
    cid = "rel_coords"
    df = _units(cid, True, seeds)
    df["width"], df["train_samples"] = width, samples
    df.loc[df["model"] == "lnn", "heldout_l1_qddot"] = NULL
    if not control:
        df.loc[df["model"] == "lnn_slow", "heldout_l1_qddot"] = NULL
    part = next(p for p in judge(CLAIMS[cid], df, "quick")["parts"] if p["name"] == "LNN on (q, qdot) learns")
    return part["verdict"], part["reason"]["jax"]


def test_a_paper_model_that_never_learns_is_not_reproduced_only_with_the_originals_chance():
    five = (0, 1, 2, 3, 4)
    verdict, why = _lnn_on_plateau(five)
    assert verdict == "not reproduced" and "learned on none of 5 seeds" in why, why
    for kw, said in (({"samples": 1e7}, "budget 16.3 % of the original's"), ({"width": "128x128x128"}, "width 128x128x128"),
                     ({}, "2 seeds (at least 5)")):
        verdict, why = _lnn_on_plateau(five if kw else (0, 1), **kw)
        assert verdict == "inconclusive" and "inconclusive: budget" in why and said in why, why
    verdict, why = _lnn_on_plateau(five, control=False)
    assert verdict == "inconclusive" and "inconclusive: pipeline" in why, why


def test_a_positive_control_that_did_not_learn_makes_a_failure_say_nothing():
    cid = "delan_table1"
    df = _units(cid, True)
    assert judge(CLAIMS[cid], df, "quick")["verdict"] == "reproduced"
    df.loc[df["model"] == "delan_control", "heldout_l1"] = NULL
    v = judge(CLAIMS[cid], df, "quick")
    assert v["verdict"] == "inconclusive" and "positive control did not learn" in v["reason"], v["reason"]


def _paces(cid, paces: dict, n=8):
    """Rows of a pooled claim: model -> its n seeds' samples to leave the plateau (default: never)."""
    return pd.DataFrame([_row(cid, m, k, {"samples_to_leave": paces.get(m, [float("inf")] * n)[k],
                                          "heldout_l1": 1.0})
                         for m in CLAIMS[cid].labels("quick") for k in range(n)])


def test_training_pace_over_seeds_is_read_on_an_interval_a_part_per_rival():
    cid, ours, inf = "init_study", "lnn_init-cranmer2020", float("inf")
    fast, slow = [1e4 + i for i in range(8)], [5e4 + i for i in range(8)]
    others = {m: slow for m in CLAIMS[cid].labels("quick") if m != ours}
    v = judge(CLAIMS[cid], _paces(cid, {ours: fast, **others}), "quick")
    assert v["verdict"] == "reproduced" and "8/8 [0.68, 1.00]" in v["reason"], v["reason"]
    # two of eight leaving against none: a small sample decides nothing
    v = judge(CLAIMS[cid], _paces(cid, {ours: [1e4, 1e4] + [inf] * 6}), "quick")
    assert v["verdict"] == "inconclusive", v["reason"]
    # nobody left the plateau: nothing to compare
    v = judge(CLAIMS[cid], _paces(cid, {}), "quick")
    assert v["verdict"] == "inconclusive" and "no seed of either got there" in v["reason"], v["reason"]
    # another init clearly faster: that part is not reproduced, and says which way
    v = judge(CLAIMS[cid], _paces(cid, {ours: slow, "lnn_init-kaiming": fast, "lnn_init-xavier": [inf] * 8,
                                        "lnn_init-pytorch_default": [inf] * 8}), "quick")
    parts = {p["name"]: p for p in v["parts"]}
    assert parts["faster than kaiming"]["verdict"] == "not reproduced"
    assert "lnn_init-kaiming faster" in parts["faster than kaiming"]["reason"]["jax"]
    assert parts["faster than xavier"]["verdict"] == "reproduced"
    assert v["verdict"] == "partly" and "not reproduced: faster than kaiming" in v["reason"], v["reason"]


def test_a_pace_study_needs_its_reference_off_the_plateau_at_the_end():
    cid, ours = "init_study", "lnn_init-cranmer2020"
    fast, slow = [1e4 + i for i in range(8)], [5e4 + i for i in range(8)]
    df = _paces(cid, {ours: fast, **{m: slow for m in CLAIMS[cid].labels("quick") if m != ours}})
    df.loc[df["model"] == ours, "heldout_l1"] = NULL * 0.9    # back on the plateau at the end
    v = judge(CLAIMS[cid], df, "quick")
    assert v["verdict"] == "inconclusive" and "below the competence bar" in v["reason"], v["reason"]


def test_plain_relu_must_never_leave_while_softplus_leaves_first():
    cid, inf = "activation_study", float("inf")
    fast, slow = [1e4 + i for i in range(8)], [5e4 + i for i in range(8)]
    smooth = {m: slow for m in CLAIMS[cid].labels("quick") if m not in ("lnn_act-softplus", "lnn_act-relu")}
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": fast, **smooth}), "quick")
    assert v["verdict"] == "reproduced" and "lnn_act-relu got there in 0/8 [0.00, 0.32]" in v["reason"], v["reason"]
    # one ReLU seed left the plateau (late): it can learn, so that part fails
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": fast, **smooth, "lnn_act-relu": [9e4] + [inf] * 7}),
              "quick")
    assert v["verdict"] == "partly" and "it can learn" in v["reason"], v["reason"]
    # nobody left, ReLU included: the ReLU part's control (softplus) did not learn, so it says nothing
    df = _paces(cid, {})
    df.loc[df["model"] == "lnn_act-softplus", "heldout_l1"] = NULL
    v = judge(CLAIMS[cid], df, "quick")
    relu = next(p for p in v["parts"] if p["name"] == "plain ReLU cannot learn")
    assert relu["verdict"] == "inconclusive" and "positive control did not learn" in relu["reason"]["jax"]
    assert v["verdict"] == "inconclusive"
    # softplus never leaves while the smooth ones do: those pace parts fail, and say which way
    v = judge(CLAIMS[cid], _paces(cid, {"lnn_act-softplus": [inf] * 8, **{m: fast for m in smooth}}), "quick")
    parts = {p["name"]: p for p in v["parts"]}
    assert parts["faster than tanh"]["verdict"] == "not reproduced" and "lnn_act-tanh faster" in v["reason"]
    assert parts["faster than relu"]["verdict"] == "inconclusive"        # neither left: nothing to order
    assert v["verdict"] == "inconclusive", v["reason"]


def test_frameworks_that_disagree_are_inconclusive_and_flagged_never_partly():
    both = pd.concat([_units("dp_loss", True, fw="jax"), _units("dp_loss", False, fw="torch")])
    v = judge(CLAIMS["dp_loss"], both, "quick")
    assert v["verdict"] == "inconclusive" and v["parts"][0]["flag"] == "frameworks disagree"
    assert v["flags"] == ["similar held-out loss: frameworks disagree"]
    weak = _units("dp_loss", True, fw="torch")
    weak["heldout_l1"] = NULL
    both = pd.concat([_units("dp_loss", True, fw="jax"), weak])
    v = judge(CLAIMS["dp_loss"], both, "quick")
    assert v["verdict"] == "inconclusive" and v["by_framework"] == {"jax": "reproduced", "torch": "inconclusive"}
    assert not v["flags"]     # one framework undecided is no disagreement
