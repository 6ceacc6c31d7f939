"""The development and test splits (`replication.run.splits`): disjoint seeds and draws; a test run's
trainings read only development data (their validation draw), its evaluations only the test draw; a
summary and a report judge one split's units, never both."""
import json

import pytest

from lagbench.replication.claims import CLAIMS, PROFILES
from lagbench.replication.run import runner, splits
from lagbench.replication.run import units as units_mod
from lagbench.replication.training import data as datamod

KW = dict(profile="smoke", claims=["dp_loss"], frameworks=("jax",), models=["baseline", "lnn"], progress=False)


def test_splits_share_no_seed_and_no_draw():
    assert splits.DEV.heldout_seed != splits.TEST.heldout_seed and splits.DEV.draw_offset != splits.TEST.draw_offset
    for profile in PROFILES:
        for c in CLAIMS.values():
            n = c.n_seeds(profile)
            dev, test = splits.DEV.seeds(n), splits.TEST.seeds(n)
            assert not set(dev) & set(test)
            assert all(splits.of_seed(s) is splits.DEV for s in dev) and all(splits.of_seed(s) is splits.TEST for s in test)
    planned = runner.plan("quick", split="test")
    assert planned and all(u.split == "test" and u.seed >= 1000 for u in planned)
    assert all(u.split == "dev" and u.seed < 1000 for u in runner.plan("quick", split="dev"))


def test_unknown_split_is_refused_by_name():
    with pytest.raises(ValueError, match="--split: unknown 'val'; valid: dev, test"):
        runner.plan("quick", split="val")


def test_more_seeds_than_a_split_holds_are_refused():
    with pytest.raises(ValueError, match="--n-seeds: 1001 is not valid"):
        runner.plan("quick", split="dev", seeds=1001)


@pytest.fixture()
def reads(monkeypatch):
    """Every held-out draw read, with the phase (training or evaluation) that read it."""
    seen, phase = [], ["evaluation"]
    real_heldout, real_train = datamod.heldout, units_mod.train_cached

    def heldout(protocol, seed=datamod.HELDOUT_SEED, **kw):
        seen.append((phase[0], seed))
        return real_heldout(protocol, seed, **kw)

    def train_cached(*a, **kw):
        phase[0] = "training"
        try:
            return real_train(*a, **kw)
        finally:
            phase[0] = "evaluation"
    monkeypatch.setattr(datamod, "heldout", heldout)
    monkeypatch.setattr(units_mod, "train_cached", train_cached)
    return seen


def test_a_test_run_trains_on_development_draws_and_decides_on_the_test_draw(tmp_path, reads):
    runner.run(out=tmp_path, split="test", **KW)
    training = {seed for phase, seed in reads if phase == "training"}
    evaluation = {seed for phase, seed in reads if phase == "evaluation"}
    assert training == {splits.DEV.heldout_seed}   # the trainings track held-out error: on the dev draw only
    assert evaluation == {splits.TEST.heldout_seed}
    results = [json.loads(p.read_text()) for p in tmp_path.glob("units/*/*/*/seed*/result.json")]
    assert results and {(r["split"], r["seed"]) for r in results} == {("test", 1000)}


def test_summary_and_report_judge_one_split(tmp_path, reads):
    from lagbench.reports.load import load_results

    runner.run(out=tmp_path, split="dev", **KW)
    dev = json.loads((tmp_path / "summary" / "verdicts.json").read_text())
    runner.run(out=tmp_path, split="test", **KW)
    test = json.loads((tmp_path / "summary" / "verdicts.json").read_text())
    assert dev["split"] == "dev" and test["split"] == "test"
    (claim,) = [c for c in test["claims"] if c["id"] == "dp_loss"]
    assert claim["seeds"] == [1000]
    assert {s for c in dev["claims"] for s in c.get("seeds", [])} == {0}
    res = load_results(tmp_path)
    assert res.split == "test" and {u.seed for u in res.units} == {"1000"}
    assert any("another split" in p for p in res.problems)
