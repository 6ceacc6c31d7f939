"""A predictor from outside the suite (`replication.predictor.score`, `lagbench evaluate --predict`): the exact
acceleration scores at the chaos floor, the zero predictor as the null, a diverging one neither."""
import json

import numpy as np
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.replication.predictor.score import score, setup

DP = systems.get("double_pendulum")


def exact(q, qdot):
    return DP.acceleration(q, qdot, backend="numpy")


def zero(q, qdot):
    return np.zeros_like(q)


@pytest.fixture(scope="module")
def scored():
    return {name: score(fn, "double_pendulum", "quick", label=name)["metrics"]
            for name, fn in (("exact", exact), ("zero", zero), ("diverging", lambda q, qd: 1e3 * qd ** 3))}


def test_the_exact_acceleration_scores_at_the_chaos_floor(scored):
    m = scored["exact"]
    assert m["heldout_l1"] == 0.0 and m["null_heldout_l1"] > 10
    # the suite's RK4 (dt 0.01) against the truth's tight dopri8: valid for most of what a 1e-8 perturbation allows
    assert 0.5 * m["chaos_floor_vpt_s"] <= m["vpt_s"] <= m["chaos_floor_vpt_s"] + 1e-9
    # the second floor, the exact model in float32 through the same RK4: no later than the 1e-8 floor
    assert 0.5 * m["chaos_floor_vpt_s"] <= m["float32_truth_vpt_s"] <= m["chaos_floor_vpt_s"] + 1e-9
    assert 0.3 < m["lyapunov_time_s"] < 3 and m["vpt_lyapunov"] > 5
    assert m["energy_err_final"] < 1e-3 and m["n_diverged"] == 0


def test_the_zero_predictor_scores_as_the_null(scored):
    m, floor = scored["zero"], scored["exact"]["chaos_floor_vpt_s"]
    assert m["null_heldout_l1"] <= m["heldout_l1"] <= 1.01 * m["null_heldout_l1"]
    assert m["vpt_s"] < 0.1 * floor and m["vpt_lyapunov"] < 1


def test_a_diverging_predictor_is_valid_for_no_time(scored):
    m = scored["diverging"]
    assert m["heldout_l1"] > m["null_heldout_l1"] and m["vpt_s"] < 0.1 * scored["exact"]["chaos_floor_vpt_s"]


def test_a_system_without_chaos_has_no_lyapunov_time():
    s = systems.get("spring")
    d = score(lambda q, qd: s.acceleration(q, qd, backend="numpy"), "spring", "smoke")   # unnamed: "predictor"
    m = d["metrics"]
    assert d["model"] == "predictor"
    assert m["heldout_l1"] == 0.0 and np.isnan(m["lyapunov_time_s"]) and m["vpt_s"] == m["chaos_floor_vpt_s"]


def test_each_system_is_scored_like_the_suites_own_model_of_it():
    s = setup("double_pendulum", "quick")
    assert (s.claim.id, s.evaluate, s.protocol.task) == ("dp_energy", "energy_rollout", "acceleration")
    assert setup("charged_magnetic", "quick").evaluate == "heldout"
    with pytest.raises(ValueError, match="--system wave: no claim scores"):
        setup("wave", "quick")


def test_the_command_writes_the_record_and_names_bad_input(tmp_path, monkeypatch, capsys):
    (tmp_path / "mine.py").write_text("import numpy as np\n\ndef zero(q, qdot):\n    return np.zeros_like(q)\n\n"
                                      "def wide(q, qdot):\n    return np.zeros((len(q), 2))\n")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "res"
    assert main(["evaluate", "--predict", "mine:zero", "--system", "pendulum", "--profile", "smoke", "--out", str(out)]) == 0
    d = json.loads((out / "predict" / "pendulum" / "zero" / "result.json").read_text())
    m = d["metrics"]   # the null predictor is the better of zero and the mean: zero is no better than it
    assert d["split"] == "test" and m["null_heldout_l1"] <= m["heldout_l1"] <= 1.01 * m["null_heldout_l1"] and d["checksum"]
    assert (out / "predict" / "pendulum" / "zero" / "rollouts.csv").is_file()
    for argv, words in ((["--predict", "mine:wide", "--system", "pendulum"], "to qddot of shape (N, 1)"),
                        (["--predict", "mine:none", "--system", "pendulum"], "cannot import it"),
                        (["--predict", "mine:zero"], "--system: required with --predict"),
                        (["--predict", "mine:zero", "--system", "pendulum", "--data", "x.csv"], "--data: not used"),
                        (["--predict", "mine", "--system", "pendulum"], "give module:function")):
        assert main(["evaluate", *argv, "--profile", "smoke", "--out", str(out)]) != 0
        err = capsys.readouterr().err
        assert words in err and "Traceback" not in err


def test_the_report_shows_verified_predictors_and_names_a_tampered_one(tmp_path):
    from lagbench.reports.build import build_sections

    for name, fn in (("exact", exact), ("zero", zero)):
        score(fn, "double_pendulum", "smoke", out=tmp_path, label=name)
    sections = build_sections(tmp_path, tmp_path / "report")
    table = next(b for s in sections if s.title == "Your predictors" for b in s.blocks if hasattr(b, "df"))
    assert list(table.df["predictor"]) == ["exact", "zero"] and table.df["held-out L1"].iloc[0] == "0"
    path = tmp_path / "predict" / "double_pendulum" / "zero" / "result.json"
    path.write_text(path.read_text().replace('"profile": "smoke"', '"profile": "quick"'))
    sections = build_sections(tmp_path, tmp_path / "report")
    texts = [b.text for s in sections if s.title == "Your predictors" for b in s.blocks if hasattr(b, "text")]
    assert any("zero: result.json checksum mismatch; not used" in t for t in texts)


def heldout_of_predictor(system, profile):
    """The held-out states a predictor of `system` is scored on."""
    from lagbench.replication.evaluation.routines import heldout_of
    from lagbench.replication.run.splits import TEST

    class Ctx:
        protocol, split = setup(system, profile).protocol, TEST
    return heldout_of(Ctx)["q"]


def test_a_function_that_raises_is_one_line_and_a_non_finite_one_is_scored_failed(tmp_path, monkeypatch, capsys):
    (tmp_path / "odd.py").write_text("import numpy as np\n\ndef raises(q, qdot):\n    return {}['key']\n\n"
                                     "def nan7(q, qdot):\n    out = np.zeros_like(q)\n    out[::7] = np.nan\n"
                                     "    return out\n")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "res"
    common = ["--system", "pendulum", "--profile", "smoke", "--out", str(out)]
    assert main(["evaluate", "--predict", "odd.py:raises", *common]) == 2
    err = capsys.readouterr().err
    assert err == ("lagbench: error: --predict odd.py:raises: raises(q, qdot) raised KeyError: 'key' (odd.py line 4, "
                   "in raises); an error in your code: a rerun fails the same way until it is fixed\n")
    assert main(["evaluate", "--predict", "odd.py:nan7", *common]) == 1
    d = json.loads((out / "predict" / "pendulum" / "nan7" / "result.json").read_text())
    n = len(heldout_of_predictor("pendulum", "smoke"))
    why = f"non-finite on {-(-n // 7)} of {n} held-out states"
    assert d["status"] == "failed" and d["failure"]["message"] == why and d["checksum"]   # the record is kept
    assert f"--predict odd.py:nan7: failed: {why}" in capsys.readouterr().err
    assert main(["table", "--results", str(out)]) == 0
    assert f"failed: {why}" in capsys.readouterr().out   # the table says why its numbers are no scores
    from lagbench.reports.build import build_sections

    table = next(b for s in build_sections(out, tmp_path / "report") if s.title == "Your predictors"
                 for b in s.blocks if hasattr(b, "df"))
    assert list(table.df["status"]) == [f"failed: {why}"]
