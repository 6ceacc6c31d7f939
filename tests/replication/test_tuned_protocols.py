"""Adopted tuning (`replication.claims.tuned`, `replication.tuning.adopt`, applied by `replication.claims.resolved`):
a `lagbench tune` ledger's choices become what a claim runs under its profile only when every model was searched
alike on the development split; claims that share trainings take the same choice; verdicts and the report say
how each model's protocol was chosen and flag a model tuned less than its rivals."""
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from lagbench.replication.claims import CLAIMS, PROFILES, get, tuned
from lagbench.replication.claims.resolved import resolved, tuning
from lagbench.replication.training.protocol import canonical_hash
from lagbench.replication.tuning import adopt

ROOT = Path(__file__).resolve().parents[2]


def _ledger(claim_id="hnn_energy", profile="quick", split="dev", tried=9, knobs=None, drop=(), kind="search",
            confirm=(0, 1, 2), first=9):
    claim = get(claim_id)
    labels = [m.label for m in claim.models if m.train and m.runs_in(profile) and m.label not in drop]
    knobs = knobs or {"lr": 1 / 3, "width": 2.0}
    return {"claim": claim_id, "profile": profile, "split": split, "search": {"lr": [1 / 3, 1, 3], "width": [0.5, 1, 2]},
            "seeds": [0], "frameworks": ["jax"], "kind": kind,
            "models": {x: {"configs_tried": tried if i else first, "scored_on": split, "chosen": 1, "chosen_knobs": knobs,
                           "confirm_seeds": list(confirm), "confirmation": {"0": 2.5, "1": 1.5},
                           "scores": {"0": 2.0, "1": 1.0}} for i, x in enumerate(labels)}}


@pytest.fixture
def record_file(tmp_path, monkeypatch):
    monkeypatch.setattr(tuned, "FILE", tmp_path / "tuned.json")
    tuned.records.cache_clear()
    yield tmp_path
    tuned.records.cache_clear()


def _write(tmp_path, ledger) -> Path:
    f = tmp_path / f"ledger_{len(list(tmp_path.iterdir()))}.json"
    f.write_text(json.dumps(ledger))
    return f


def test_adopt_applies_the_choice_under_its_profile_only(record_file):
    rec = adopt.adopt(_write(record_file, _ledger()), today="2026-01-01")
    assert rec["split"] == "dev" and rec["configs"] == 9 and rec["adopted"] == "2026-01-01"
    assert all(m["score"] == 1.5 and m["confirm_seeds"] == [0, 1, 2] for m in rec["models"].values())
    written = get("hnn_energy")
    runs = {p: resolved(written, p) for p in PROFILES}
    for w in written.models:
        q = runs["quick"].model(w.label)
        assert q.hidden == tuple(2 * x for x in w.widths("quick")) and q.adopted.knobs == {"lr": 1 / 3, "width": 2.0}
        assert q.protocol.schedule.lr == pytest.approx(w.protocol(written.protocol("quick"), "quick").schedule.lr / 3)
        for p in ("smoke", "paper"):
            m = runs[p].model(w.label)
            assert m.adopted is None and m.hidden == w.widths(p) and m.protocol == w.protocol(written.protocol(p), p)
        # full: claim 10 is silent about it (its models run there as under quick), so quick's choice serves it
        full = runs["full"].model(w.label)
        assert full.hidden == q.hidden and full.protocol == q.protocol and full.adopted == q.adopted
    t = tuning(written, "quick")
    assert all(x["configs_tried"] == 9 and x["scored_on"] == "dev" for x in t.values()) and tuned.equal(t)
    assert tuning(written, "full") == t
    assert all(x["configs_tried"] == 0 and x["scored_on"] is None for x in tuning(written, "paper").values())


def test_a_profile_that_runs_otherwise_than_quick_keeps_its_own_setting(record_file):
    adopt.adopt(_write(record_file, _ledger("dp_loss", knobs={"lr": 3.0, "width": 2.0})))
    written = get("dp_loss")
    assert resolved(written, "quick").model("lnn").hidden != written.entry("lnn").widths("quick")
    assert resolved(written, "full").model("lnn").hidden == written.entry("lnn").widths("full")   # full trains longer
    assert all(x["configs_tried"] == 0 for x in tuning(written, "full").values())


@pytest.mark.parametrize("ledger, says", [
    (_ledger(split="test"), "development split"),
    (_ledger(tried=10), "unequal"),
    (_ledger(tried=4, first=4), "the search has 9"),
    (_ledger(kind="partial search"), "not the whole declared search"),
    (_ledger(kind="width sweep"), "not the whole declared search"),
    (_ledger(confirm=(0,)), "not confirmed on 3"),
    (_ledger(drop=("baseline_spring",)), "baseline_spring"),
    ({"models": {}}, "not a ledger"),
])
def test_adopt_refuses_a_ledger_that_is_not_an_equal_dev_search(record_file, ledger, says, capsys):
    f = _write(record_file, ledger)
    with pytest.raises(ValueError, match=says):
        adopt.adopt(f)
    assert not tuned.FILE.exists()
    with pytest.raises(SystemExit) as e:
        adopt.main([str(f)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err


def test_claims_that_share_trainings_take_the_same_choice(record_file):
    adopt.adopt(_write(record_file, _ledger("dp_loss", profile="smoke", knobs={"lr": 3.0, "width": 0.5})))
    loss, energy, precision = (resolved(get(c), "smoke") for c in ("dp_loss", "dp_energy", "precision"))
    for label, same in (("lnn", energy.model("lnn")), ("baseline", energy.model("baseline")),
                        ("baseline", precision.model("baseline_f32"))):
        a = loss.model(label)
        assert a.hidden == same.hidden == tuple(w // 2 for w in get("dp_loss").entry(label).widths("smoke"))
        assert a.protocol.schedule == same.protocol.schedule and a.protocol.scouting == same.protocol.scouting
        assert same.adopted.claim == "dp_loss" and same.adopted.label == label


def test_a_claim_that_trains_under_another_profiles_protocol_takes_that_profiles_choice(record_file):
    """Claim 11's full trains claim 1's quick protocol at quick's widths: claim 1's quick search chose for it,
    and a search of claim 1 at full's own budget does not."""
    adopt.adopt(_write(record_file, _ledger("dp_loss", knobs={"lr": 1.0, "width": 4.0})))
    adopt.adopt(_write(record_file, _ledger("dp_loss", profile="full", knobs={"lr": 1 / 3, "width": 0.5})))
    quick_loss, full_loss = resolved(get("dp_loss"), "quick"), resolved(get("dp_loss"), "full")
    written, precision = get("precision"), resolved(get("precision"), "full")
    for dtype in ("f32", "f64"):
        m, w = precision.model(f"baseline_{dtype}"), written.entry(f"baseline_{dtype}")
        assert m.hidden == quick_loss.model("baseline").hidden == tuple(4 * x for x in w.widths("full"))
        assert m.protocol.schedule == quick_loss.model("baseline").protocol.schedule
        assert (m.adopted.claim, m.adopted.profile) == ("dp_loss", "quick")
    assert full_loss.model("baseline").hidden == tuple(x // 2 for x in get("dp_loss").entry("baseline").widths("full"))
    assert all(x["configs_tried"] == 9 for x in tuning(written, "full").values())


def test_every_adopted_choice_is_its_committed_ledgers():
    """Each record of tuned.json names the ledger it came from by hash; that ledger is committed (at the
    record's `ledger` path; an earlier search's under docs/lab/tuning/<claim>/ for quick or
    docs/lab/tuning/<claim>_<profile>/) and chose exactly those knobs, on the development split, for every
    model alike."""
    for claim_id, per in tuned.records().items():
        for profile, rec in per.items():
            folder = claim_id if profile == "quick" else f"{claim_id}_{profile}"
            path = ROOT / rec["ledger"] if "ledger" in rec else ROOT / "docs" / "lab" / "tuning" / folder / "ledger.json"
            ledger = json.loads(path.read_text())
            assert canonical_hash(ledger, 16) == rec["ledger_hash"] and ledger["profile"] == profile
            assert ledger["split"] == rec["split"] == "dev"
            for label, m in rec["models"].items():
                assert ledger["models"][label]["chosen_knobs"] == m["knobs"]
            assert tuned.equal(tuning(get(claim_id), profile))


def test_what_runs_is_the_written_claim_with_exactly_the_adopted_knobs():
    """Per claim, profile and model: the adopted record `resolved` names holds the knobs it applied (the rate and
    every width a multiple of the written ones, as `search.apply` makes a configuration); a model without one
    runs as written."""
    from lagbench.replication.tuning import search

    records = tuned.records()
    applied = 0
    for claim in CLAIMS.values():
        for profile in PROFILES:
            base = claim.protocol(profile)
            for m in resolved(claim, profile).models:
                w, a = claim.entry(m.label), m.adopted
                knobs = a.knobs if a else search.REGISTERED
                if a:
                    assert records[a.claim][a.profile]["models"][a.label]["knobs"] == knobs
                    applied += 1
                entry = search.apply(w, base, profile, knobs)
                assert m.hidden == entry.widths(profile) and m.protocol == entry.protocol(base, profile)
                assert m.spec == w.spec_fields(profile) and m.train == w.train
    assert applied   # tuned.json's choices reach what runs


def test_report_flags_a_model_tuned_less_than_its_rivals():
    from lagbench.reports import sections_registration as sr

    def prereg(tuning):
        return {"protocol_hash": "x", "registered": True, "frozen": "2026-01-01", "registrations": 1, "tuning": tuning}
    t = {"configs_tried": 9, "scored_on": "dev", "knobs": {"lr": 1.0, "width": 2.0}, "seeds": [0], "confirm_seeds": [0, 1, 2]}
    hand = {"configs_tried": 0, "scored_on": None, "knobs": None, "seeds": []}
    partial = {**t, "configs_tried": 4, "confirm_seeds": []}   # an earlier search: 4 configurations, one seed
    res = SimpleNamespace(claims=[{"id": "a"}, {"id": "b"}, {"id": "c"}, {"id": "d"}], run={"profile": "quick"},
                          verdict_profile="quick",
                          verdicts={"a": {"preregistration": prereg({"lnn": t, "baseline": hand})},
                                    "b": {"preregistration": prereg({"hnn": t, "baseline": t})},
                                    "c": {"preregistration": prereg({"lgn": hand})},
                                    "d": {"preregistration": prereg({"lgn": partial})}})
    reg = sr.registration_table(res).set_index("claim")["tuning"]
    assert reg["a"].startswith("UNEQUAL") and "9 configurations per model (dev)" in reg["b"] and reg["c"] == "by hand, no search"
    ledger = sr.tuning_table(res).set_index(["claim", "model"])
    assert ledger.loc[("a", "baseline"), "flag"] == "LESS TUNING than a rival"
    assert ledger.loc[("d", "lgn"), "flag"] == "partial search (4 of 9); unconfirmed: one seed"
    assert ledger.loc[("b", "hnn"), "flag"] == "none" and ledger.loc[("b", "hnn"), "confirmed on"] == "0, 1, 2"
    assert set(ledger.index.get_level_values(0)) == {"a", "b", "d"}


def test_a_bounded_edge_step_reaches_the_record_the_verdicts_and_the_report(record_file):
    from lagbench.reports import sections_registration as sr
    ledger = {**_ledger("dp_loss", profile="full"), "edge_limits": {"width": 2.0},
              "edge_stopped": [{"lr": 3.0, "width": 4.0}]}
    rec = adopt.adopt(_write(record_file, ledger))
    assert rec["edge_limits"] == {"width": 2.0}
    t = tuning(get("dp_loss"), "full")
    assert t and all(x["edge_limits"] == {"width": 2.0} for x in t.values())
    assert all("edge_limits" not in x for x in tuning(get("dp_loss"), "quick").values())   # quick's record: none
    res = SimpleNamespace(claims=[{"id": "dp_loss"}], run={"profile": "full"}, verdict_profile="full",
                          verdicts={"dp_loss": {"preregistration": {"tuning": t}}})
    flags = sr.tuning_table(res)["flag"]
    assert all("edge step bounded (width at most x2, every model alike)" in f for f in flags)


def test_the_scorecard_says_in_one_paragraph_how_each_claim_was_chosen():
    from lagbench.reports import sections_registration as sr

    t = {"configs_tried": 4, "scored_on": "dev", "knobs": {"lr": 1.0, "width": 2.0}, "seeds": [0]}
    hand = {"configs_tried": 0, "scored_on": None, "knobs": None, "seeds": []}
    pre = {"protocol_hash": "x", "registered": True, "frozen": "2026-01-01", "registrations": 1}
    res = SimpleNamespace(claims=[{"id": "a", "number": 1}, {"id": "b", "number": 2}, {"id": "c", "number": 5}],
                          verdicts={"a": {"preregistration": {**pre, "tuning": {"lnn": t, "baseline": t}}},
                                    "b": {"preregistration": {**pre, "tuning": {"lnn": hand}, "registered": False}},
                                    "c": {"preregistration": {**pre, "tuning": {}}}})
    text = sr.summary(res)
    assert "claim 1: lagbench tune: 4 configurations per model (dev)" in text
    assert "claim 2: by hand, no search" in text and "claim 5: no trained model" in text
    assert "NOT REGISTERED (changed since their registration): b" in text


def test_every_data_file_the_package_reads_ships_in_it():
    """A JSON file beside the code (registrations, adopted tuning) is package data: a wheel without it would
    run other protocols than the repository's."""
    import tomllib

    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for f in ROOT.glob("replication/**/*.json"):
        package = ".".join(("lagbench", *f.parent.relative_to(ROOT).parts))
        assert f.name in data.get(package, []), f"{f.relative_to(ROOT)} is not package data in pyproject.toml"


def test_a_missing_adopted_tuning_file_is_an_error(tmp_path, monkeypatch):
    monkeypatch.setattr(tuned, "FILE", tmp_path / "absent.json")
    tuned.records.cache_clear()
    try:
        with pytest.raises(RuntimeError, match="missing"):
            tuned.records()
    finally:
        tuned.records.cache_clear()


def test_the_control_claim_trains_claim_9s_models_with_its_choice(record_file):
    adopt.adopt(_write(record_file, _ledger("delan_arm", profile="smoke", knobs={"lr": 3.0, "width": 0.5})))
    arm, control = (resolved(get(c), "smoke") for c in ("delan_arm", "delan_tracking"))
    for label in ("delan", "ff"):
        a, b = arm.model(label), control.model(label)
        assert a.hidden == b.hidden == tuple(w // 2 for w in get("delan_arm").entry(label).widths("smoke"))
        assert a.protocol == b.protocol
