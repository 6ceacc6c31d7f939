"""`lagbench tune` (`replication.tuning`): the same declared configurations for every model of a claim,
trained and scored on the development split only, the lowest development score chosen, the claim itself
unchanged."""
import json

import pytest

from replication.claims import get, untuned
from replication.claims.registration import protocol_hash
from replication.cli import main
from replication.run import splits
from replication.training import data as datamod
from replication.tuning import search
from replication.tuning.tune import tune


def test_configs_start_from_the_registered_setting_and_are_distinct():
    c = search.configs(5)
    assert c[0] == search.REGISTERED and len({json.dumps(x, sort_keys=True) for x in c}) == 5
    assert search.configs(5) == c   # the same list every time, for every model
    with pytest.raises(ValueError, match="--configs"):
        search.configs(0)


def test_apply_changes_only_the_knobs():
    claim = untuned("dp_loss")
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
    ledger = tune("dp_loss", profile="smoke", n_configs=2, n_seeds=1, out=tmp_path, progress=False)
    assert set(seen) == {splits.DEV.heldout_seed}   # never the test draw
    assert ledger["split"] == "dev" and ledger["seeds"] == [0]
    models = ledger["models"]
    assert set(models) == {"lnn", "baseline"}
    for m in models.values():
        assert m["configs_tried"] == 2 and m["scored_on"] == "dev"
        scores = {int(k): v for k, v in m["scores"].items()}
        finite = {k: v for k, v in scores.items() if v is not None}
        assert m["chosen"] == min(finite, key=finite.get)
    assert json.loads((tmp_path / "ledger.json").read_text())["models"] == json.loads(json.dumps(models))
    assert protocol_hash(get("dp_loss"), "smoke") == before   # the claim is untouched
    # a rerun into the same folder reads the finished units back: nothing trained or evaluated again
    ran = []
    monkeypatch.setattr("replication.tuning.tune.run_units", lambda units, *a, **k: ran.append(units))
    again = tune("dp_loss", profile="smoke", n_configs=2, n_seeds=1, out=tmp_path, progress=False)
    assert ran == [] and again["models"] == ledger["models"]


def test_tune_command_refuses_a_bad_count_in_one_line(tmp_path, capsys):
    assert main(["tune", "--claim", "dp_loss", "--profile", "smoke", "--configs", "99", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--configs" in err


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
    monkeypatch.setattr("replication.tuning.tune.run_units", lambda units, *a, **k: trained.append(units))
    ledger = tune("dp_loss", profile="smoke", n_seeds=1, out=tmp_path, progress=False, widths=["2"])
    assert ledger["kind"] == "width sweep" and ledger["search"] == {"lr": [1.0], "width": [1.0, 2.0]}
    assert all(m["configs_tried"] == 2 for m in ledger["models"].values())
    widths = [{u.entry.label: u.entry.widths("smoke") for u in units} for units in trained]
    base = untuned("dp_loss").entry("lnn").widths("smoke")
    assert widths == [{"lnn": base, "baseline": base}, {"lnn": tuple(2 * w for w in base), "baseline": tuple(2 * w for w in base)}]


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
