"""`lagbench tune` (`replication.tuning`): the same declared configurations for every model of a claim,
trained and scored on the development split only, the lowest development score chosen, the claim itself
unchanged."""
import json

import pytest

from lagbench.cli import main
from lagbench.replication.claims import get
from lagbench.replication.claims.registration import protocol_hash
from lagbench.replication.run import splits
from lagbench.replication.training import data as datamod
from lagbench.replication.tuning import choose, records, search
from lagbench.replication.tuning import tune as tune_module
from lagbench.replication.tuning.tune import tune


def test_configs_start_from_the_registered_setting_and_are_distinct():
    c = search.configs(5)
    assert c[0] == search.REGISTERED and len({json.dumps(x, sort_keys=True) for x in c}) == 5
    assert search.configs(5) == c   # the same list every time, for every model
    with pytest.raises(ValueError, match="--configs"):
        search.configs(0)


def test_the_grid_is_every_combination_with_the_registered_setting_first():
    g = search.grid()
    assert len(g) == search.SIZE == 9 and g[0] == search.REGISTERED
    assert {(c["lr"], c["width"]) for c in g} == {(a, b) for a in search.KNOBS["lr"] for b in search.KNOBS["width"]}


def test_a_choice_on_an_edge_is_extended_one_step_in_that_direction_only():
    g = search.grid()
    inner = {"lr": 1.0, "width": 1.0}
    assert search.extensions(g, [inner]) == []   # inside the grid: nothing to extend
    assert search.extensions(g, [{"lr": 1.0, "width": 2.0}]) == [{"lr": 1.0, "width": 4.0}]
    corner = search.extensions(g, [{"lr": 1 / 3, "width": 0.5}])
    assert corner == [{"lr": 1 / 9, "width": 0.5}, {"lr": 1 / 3, "width": 0.25}]
    # two models choosing the same edge add it once; the union is what every model tries
    both = search.extensions(g, [{"lr": 1.0, "width": 2.0}, {"lr": 1.0, "width": 2.0}, {"lr": 3.0, "width": 1.0}])
    assert both == [{"lr": 1.0, "width": 4.0}, {"lr": 9.0, "width": 1.0}]


def test_an_edge_limit_keeps_a_step_out_for_every_model_and_names_it():
    g, best = search.grid(), [{"lr": 3.0, "width": 2.0}, {"lr": 1.0, "width": 2.0}]
    assert search.extensions(g, best) == [{"lr": 9.0, "width": 2.0}, {"lr": 3.0, "width": 4.0}, {"lr": 1.0, "width": 4.0}]
    assert search.extensions(g, best, {"width": 2.0}) == [{"lr": 9.0, "width": 2.0}]
    assert search.stopped(g, best, {"width": 2.0}) == [{"lr": 3.0, "width": 4.0}, {"lr": 1.0, "width": 4.0}]
    assert search.stopped(g, best) == [] and search.extensions(g, best, {}) == search.extensions(g, best)
    # claim 1 under full: declared, on widths only
    assert search.EDGE_LIMITS[("dp_loss", "full")] == {"width": 2.0}


def _fake_search(monkeypatch, score):
    """The search's stages on a made-up score(model, knobs, seed): no training, the choices and the record only."""
    monkeypatch.setattr(tune_module, "run_units", lambda *a, **k: None)

    def row(self, key, u, k, knobs):
        return {"key": key, "claim": self.claim.id, "profile": self.profile, "model": u.entry.label,
                "config": k, "knob_lr": knobs["lr"], "knob_width": knobs["width"], "framework": u.framework,
                "seed": u.seed, "split": u.split, "status": "ok", "metric": choose.PACE if self.claim.pooled else "heldout_l1",
                "score": score(u.entry.label, knobs, u.seed), "train_time_s": 1.0, "train_samples": 10, "cpu": "x"}
    monkeypatch.setattr(tune_module._Runner, "_row", row)


def test_the_whole_search_extends_an_edge_for_every_model_and_confirms_on_three_seeds(tmp_path, monkeypatch):
    def score(label, knobs, seed):
        if label == "lnn":   # best at the largest width: an edge, so width x 4 is tried (by both models)
            return 1.0 / knobs["width"] + 0.01 * abs(knobs["lr"] - 1)
        # the baseline: config (lr 3, width 1) best on seed 0 by luck, the registered one on seeds 1 and 2
        lucky = knobs == {"lr": 3.0, "width": 1.0}
        return (0.5 if seed == 0 else 3.0) if lucky else 1.0 + 0.1 * seed
    _fake_search(monkeypatch, score)
    record = tmp_path / "record" / "units.csv"
    ledger = tune("dp_loss", profile="smoke", out=tmp_path / "out", progress=False, record=record)
    assert ledger["kind"] == "search" and ledger["stages"] == ["grid", "edge", "confirmation"]
    lnn, base = ledger["models"]["lnn"], ledger["models"]["baseline"]
    assert lnn["configs_tried"] == base["configs_tried"] == 11   # the grid, width x 4 and lr x 9 for both
    assert ledger["configs"][9] == {"lr": 1.0, "width": 4.0} and ledger["configs"][10] == {"lr": 9.0, "width": 1.0}
    assert lnn["chosen_knobs"] == {"lr": 1.0, "width": 4.0} and lnn["confirm_seeds"] == [0, 1, 2]
    assert set(lnn["confirmation"]) == {9, 0}
    assert base["first_choice"] == 7 and base["chosen"] == 0   # the lucky seed is overruled by the confirmation
    assert base["confirmation"][7] == pytest.approx((0.5 + 3 + 3) / 3)
    assert ledger["compute"]["units"] == len(records.read(record))
    # a fresh machine with the committed record: nothing trained again, the same ledger
    monkeypatch.setattr(tune_module._Runner, "_row", lambda *a: pytest.fail("a recorded unit was redone"))
    again = tune("dp_loss", profile="smoke", out=tmp_path / "fresh", progress=False, record=record)
    assert again["models"] == ledger["models"]
    assert json.loads((record.parent / "ledger.json").read_text())["models"] == json.loads(json.dumps(ledger["models"]))
    from lagbench.replication.tuning import summary
    text = summary.table([record.parent / "ledger.json"])
    assert "| dp_loss | smoke | lnn | 11 | lr x1, width x4 |" in text and "| dp_loss | smoke | baseline | 11 | lr x1, width x1 |" in text


def test_a_declared_edge_limit_stops_the_step_for_both_models_and_the_ledger_says_so(tmp_path, monkeypatch, capsys):
    _fake_search(monkeypatch, lambda label, knobs, seed: 1.0 / knobs["width"] + abs(knobs["lr"] - 1) + seed)  # widest best
    monkeypatch.setitem(search.EDGE_LIMITS, ("dp_loss", "smoke"), {"width": 2.0})
    assert main(["tune", "--claim", "dp_loss", "--profile", "smoke", "--out", str(tmp_path), "--quiet"]) == 0
    assert "edge step bounded (width at most x2, every model alike): not tried lr x1 width x4" in capsys.readouterr().out
    ledger = json.loads((tmp_path / "ledger.json").read_text())
    assert all(m["configs_tried"] == 9 for m in ledger["models"].values())   # width x 4 tried by neither
    assert ledger["edge_limits"] == {"width": 2.0} and ledger["edge_stopped"] == [{"lr": 1.0, "width": 4.0}]
    assert all(m["chosen_knobs"] == {"lr": 1.0, "width": 2.0} for m in ledger["models"].values())


def test_an_ablation_gives_every_arm_one_configuration(tmp_path, monkeypatch):
    prefer = {"lnn_init-cranmer2020": 2.0, "lnn_init-xavier": 1.0, "lnn_init-kaiming": 1.0, "lnn_init-pytorch_default": 0.5}

    def score(label, knobs, seed):   # each arm's own best width differs; most arms prefer width x 1
        return 1000.0 * (1 + abs(knobs["width"] - prefer[label])) * (1 + abs(knobs["lr"] - 1)) + seed
    _fake_search(monkeypatch, score)
    ledger = tune("init_study", profile="smoke", n_seeds=2, out=tmp_path, progress=False)
    chosen = {m["chosen"] for m in ledger["models"].values()}
    assert len(chosen) == 1 and ledger["configs"][chosen.pop()] == {"lr": 1.0, "width": 1.0}
    assert "mean_rank" in ledger["joint"] and all(m["confirm_seeds"] == [0, 1] for m in ledger["models"].values())


def test_apply_changes_only_the_knobs():
    claim = get("dp_loss")
    entry = claim.entry("lnn")
    base = claim.protocol("quick")
    p0 = entry.protocol(base, "quick")
    same = search.apply(entry, base, "quick", search.REGISTERED)
    assert same.protocol(base, "quick") == p0 and same.widths("quick") == entry.widths("quick")
    other = search.apply(entry, base, "quick", {"lr": 3.0, "width": 0.5})
    p = other.protocol(base, "quick")
    assert p.schedule.lr == pytest.approx(3 * p0.schedule.lr)
    assert p.scouting.schedule.lr == pytest.approx(3 * p0.scouting.schedule.lr)
    assert other.widths("quick") == tuple(w // 2 for w in entry.widths("quick"))
    assert p.replace(**{"schedule.lr": p0.schedule.lr, "scouting.schedule.lr": p0.scouting.schedule.lr}) == p0   # the budget and everything else as registered
    for q in ("smoke", "full", "paper"):   # the other profiles as registered
        assert other.widths(q) == entry.widths(q)
        assert other.protocol(claim.protocol(q), q) == entry.protocol(claim.protocol(q), q)


def test_tune_searches_every_model_alike_on_the_development_split_only(tmp_path, monkeypatch):
    seen = []
    real = datamod.heldout

    def heldout(protocol, seed=datamod.HELDOUT_SEED, **kw):
        seen.append(seed)
        return real(protocol, seed, **kw)
    monkeypatch.setattr(datamod, "heldout", heldout)
    before = protocol_hash(get("dp_loss"), "smoke")
    ledger = tune("dp_loss", profile="smoke", n_configs=2, n_seeds=1, out=tmp_path, progress=False,
                  record=tmp_path / "units.csv")
    assert set(seen) == {splits.DEV.heldout_seed}   # never the test draw
    assert ledger["split"] == "dev" and ledger["seeds"] == [0] and ledger["kind"] == "partial search"
    rows = records.read(tmp_path / "units.csv")
    assert len(rows) == 4 and {r["metric"] for r in rows.values()} == {"heldout_l1"}
    models = ledger["models"]
    assert set(models) == {"lnn", "baseline"}
    for m in models.values():
        assert m["configs_tried"] == 2 and m["scored_on"] == "dev"
        scores = {int(k): v for k, v in m["scores"].items()}
        finite = {k: v for k, v in scores.items() if v is not None}
        assert m["chosen"] == min(finite, key=finite.get)
    assert json.loads((tmp_path / "ledger.json").read_text())["models"] == json.loads(json.dumps(models))
    assert protocol_hash(get("dp_loss"), "smoke") == before   # the claim is untouched
    # two worker processes train a configuration's models side by side: the same units, each trained at its
    # own configuration (not the claim's registered one), the same scores up to the rounding of one thread
    par = tune("dp_loss", profile="smoke", n_configs=2, n_seeds=1, out=tmp_path / "jobs2", progress=False,
               record=tmp_path / "jobs2.csv", jobs=2)
    scores = {k: r["score"] for k, r in records.read(tmp_path / "jobs2.csv").items()}
    assert scores == pytest.approx({k: r["score"] for k, r in rows.items()}, rel=1e-4)
    assert {m["chosen"] for m in par["models"].values()} == {m["chosen"] for m in ledger["models"].values()}
    # a rerun into the same folder reads the finished units back: nothing trained or evaluated again
    ran = []
    monkeypatch.setattr("lagbench.replication.tuning.tune.run_units", lambda units, *a, **k: ran.append(units))
    again = tune("dp_loss", profile="smoke", n_configs=2, n_seeds=1, out=tmp_path, progress=False)
    assert ran == [] and again["models"] == ledger["models"]
    # a changed protocol is another unit: its recorded row is not reused
    u = tune_module._Runner(get("dp_loss"), "smoke", ["lnn"], ("jax",), tmp_path, None, False).units(
        search.REGISTERED, ["lnn"], [0])[0]
    assert records.unit_key(u) in rows
    import dataclasses
    other = dataclasses.replace(u, entry=search.apply(u.entry, u.claim.protocol("smoke"), "smoke", {"lr": 1.0, "width": 1.5}))
    assert records.unit_key(other) not in rows


def test_tune_command_refuses_a_bad_count_in_one_line(tmp_path, capsys):
    assert main(["tune", "--claim", "dp_loss", "--profile", "smoke", "--configs", "99", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--configs" in err
    assert main(["tune", "--claim", "dp_loss", "--profile", "smoke", "--jobs", "0", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--jobs" in err


def test_a_width_sweep_gives_every_model_the_registered_setting_then_each_width():
    assert search.sweep(["2", "4", "2", "1"]) == [search.REGISTERED, {"lr": 1.0, "width": 2.0}, {"lr": 1.0, "width": 4.0}]
    for bad in (["0"], ["x"], [], ["inf"]):
        with pytest.raises(ValueError, match="--widths"):
            search.sweep(bad)


def test_tune_command_runs_a_width_sweep_and_refuses_a_bad_one_in_one_line(tmp_path, capsys, monkeypatch):
    assert main(["tune", "--claim", "dp_loss", "--profile", "smoke", "--widths", "2,-1", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--widths" in err
    trained = []   # the units each configuration trains (the training itself is the search test's above)
    monkeypatch.setattr("lagbench.replication.tuning.tune.run_units", lambda units, *a, **k: trained.append(units))
    ledger = tune("dp_loss", profile="smoke", n_seeds=1, out=tmp_path, progress=False, widths=["2"])
    assert ledger["kind"] == "width sweep" and ledger["search"] == {"lr": [1.0], "width": [1.0, 2.0]}
    assert all(m["configs_tried"] == 2 for m in ledger["models"].values())
    widths = [{u.entry.label: u.entry.widths("smoke") for u in units} for units in trained]
    base = get("dp_loss").entry("lnn").widths("smoke")
    double = tuple(2 * w for w in base)   # each model's units of a configuration run as one (the record grows per model)
    assert widths == [{"lnn": base}, {"baseline": base}, {"lnn": double}, {"baseline": double}]


def test_a_pace_study_is_tuned_by_its_pace_over_a_sample_of_seeds(tmp_path):
    import pandas as pd

    ledger = tune("init_study", profile="smoke", n_configs=1, n_seeds=2, out=tmp_path, progress=False)
    assert "samples_to_leave" in ledger["scored_by"] and ledger["seeds"] == [0, 1]
    rows = pd.read_csv(tmp_path / "ledger.csv")
    for label, m in ledger["models"].items():
        g = rows[rows["model"] == label]
        for k, v in m["scores"].items():
            assert v == g[g["config"] == int(k)]["score"].median()   # the median over the seeds, +inf kept
    r = json.loads((tmp_path / "config0/units/init_study/jax/lnn_init-kaiming/seed0/result.json").read_text())
    assert rows[(rows["model"] == "lnn_init-kaiming") & (rows["config"] == 0) & (rows["seed"] == 0)]["score"].item() \
        == r["metrics"]["samples_to_leave"]


def test_claim_13s_online_learners_are_searched_and_learn_at_their_protocols_rate(tmp_path, monkeypatch):
    """Claim 13's models learn inside their evaluation (`train=False`): the search gives them the same grid as
    a training's, and the online learner takes the unit's rate and widths."""
    from types import SimpleNamespace

    from lagbench.replication.claims import tuned
    from lagbench.replication.evaluation import online_claim
    from lagbench.replication.studies import online_learner

    claim = get("delan_online")
    assert [m.label for m in claim.models if tuned.searched(claim, m, "quick")] == ["delan", "ff"]
    _fake_search(monkeypatch, lambda label, knobs, seed: knobs["lr"] * knobs["width"])
    ledger = tune("delan_online", profile="smoke", out=tmp_path, progress=False)
    assert set(ledger["models"]) == {"delan", "ff"} and all(m["configs_tried"] >= 9 for m in ledger["models"].values())
    seen = {}
    monkeypatch.setattr(online_learner, "learner", lambda kind, fw, seed, hidden, lr=None: seen.update(lr=lr, hidden=hidden))
    u = tune_module._Runner(claim, "smoke", ["delan"], ("jax",), tmp_path, None, False).units(
        {"lr": 3.0, "width": 2.0}, ["delan"], [0])[0]
    ctx = SimpleNamespace(model=None, spec=u.spec(), protocol=u.protocol(), framework="jax", seed=0)
    online_claim._controller(ctx, {"steps": 1})
    assert seen["lr"] == pytest.approx(3 * claim.protocol("smoke").schedule.lr)
    assert seen["hidden"] == tuple(2 * w for w in claim.entry("delan").widths("smoke"))
