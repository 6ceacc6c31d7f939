"""The dissipative fit of docs/fit.md ('Friction: a dissipative fit'), run as written from its own text: on a
pendulum with viscous friction 0.3, the LNN with a learned Rayleigh function recovers the friction (the default
run: the block's data and its dissipative fit) and rolls out better than the conservative LNN, which cannot lose
energy; the baseline, trained alike, tracks best (`tox -e slow`: the whole block). DeLaN with a learned Rayleigh
function on the same data reads the friction through the same checks."""
import dataclasses
import json
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.files import user_data
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.evaluation.routines import Evaluation
from lagbench.replication.fit.dissipation import (
    ABLATION_MIN,
    BRACKET_MIN,
    HESSIAN_RESIDUAL_MAX,
    OFF,
    dissipation_metrics,
    softplus,
    with_coefficients,
    without_dissipation_l1,
)
from lagbench.replication.fit.load import Padded, load_fitted

DOC = Path(__file__).resolve().parents[3] / "docs" / "fit.md"
MARKER = "<!-- dissipative example: tests/replication/fit/test_fit_dissipation.py runs this block -->"


def _block() -> list[list[str]]:
    text = DOC.read_text(encoding="utf-8")
    block = re.search(r"```bash\n(.*?)```", text[text.index(MARKER):], re.S).group(1)
    commands = [shlex.split(ln)[1:] for ln in block.splitlines() if ln.startswith("lagbench ")]
    assert [c[0] for c in commands] == ["simulate", "simulate", "fit", "fit", "fit", "report"]
    assert "--dissipation" in commands[2]
    return commands


def _run(folder, commands):
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(folder)
        for args in commands:
            assert main([*args, "--quiet"] if args[0] == "fit" else args) == 0, args


def _metrics(folder) -> dict:
    return {p.parts[-3]: json.loads(p.read_text())["metrics"]
            for p in folder.glob("results/friction/units/fit/*/*/seed0/result.json")}


@pytest.fixture(scope="module")
def dissipative_folder(tmp_path_factory):
    """The block's data, its dissipative fit and the report of that fit (the default run's part of the block)."""
    folder = tmp_path_factory.mktemp("friction")
    block = _block()
    _run(folder, [*block[:3], block[5]])
    report = (folder / "report" / "friction" / "REPORT.md").read_text()
    assert "one-step error without the learned friction / with it" in report
    return folder


@pytest.fixture(scope="module")
def friction_folder(dissipative_folder):
    """The whole block: the conservative LNN and the baseline fitted beside it, and the report of all three."""
    _run(dissipative_folder, _block()[3:])
    report = (dissipative_folder / "report" / "friction" / "REPORT.md").read_text()
    assert "Recommended on this data: baseline (jax, seed 0)" in report   # the others over 2 x its rollout error
    return dissipative_folder


@pytest.fixture(scope="module")
def delan_folder(dissipative_folder):
    """DeLaN with a learned Rayleigh function on the block's data, at its defaults but for 2 000 steps, in a folder
    of its own (the block's report compares the three fits it names)."""
    data = "results/friction_data/"
    _run(dissipative_folder, [["fit", "--data", data + "train.csv", "--test", data + "test.csv", "--system", "pendulum",
                               "--model", "delan", "--dissipation", "on", "--periodic", "none", "--steps", "2000",
                               "--out", "results/friction_delan"]])
    return dissipative_folder


def _fitted(folder, kind):
    out = "friction_delan" if kind == "delan_dissipative" else "friction"
    return load_fitted(next(folder.glob(f"results/{out}/units/fit/*/{kind}/seed0")))


def test_the_dissipative_delan_recovers_the_friction(delan_folder):
    """DeLaN's Lagrangian is quadratic in qdot, its velocity Hessian its mass matrix: the friction is read off
    b / |c| against that, through the same checks as an LNN's."""
    m = _fitted(delan_folder, "delan_dissipative").result["metrics"]
    assert m["test_dissipation_coefficient_0"] == pytest.approx(0.3, rel=0.1)
    assert m["test_dissipation_hessian_residual"] < 0.1
    assert m["test_dissipation_bracket_half"] >= BRACKET_MIN and m["test_dissipation_bracket_double"] >= BRACKET_MIN
    assert m["test_l1"] < 0.1 * m["null_test_l1"]


def test_the_dissipative_lnn_recovers_the_friction(dissipative_folder):
    m = _metrics(dissipative_folder)["lnn_dissipative"]
    assert m["test_dissipation_coefficient_0"] == pytest.approx(0.3, rel=0.1)
    assert m["test_dissipation_ablation"] >= ABLATION_MIN   # the friction carries its accuracy
    # ... and the test file's rollouts single it out: less friction and more each roll out worse
    assert m["test_dissipation_bracket_half"] >= BRACKET_MIN and m["test_dissipation_bracket_double"] >= BRACKET_MIN
    assert m["test_l1"] < 0.1 * m["null_test_l1"]


def test_a_fit_whose_friction_carries_nothing_reports_none(dissipative_folder):
    """The same trained model with its dissipation removed: it still learned (better than the null) and its
    velocity Hessian is as close to c M, but the friction it would report explains nothing of the data."""
    f = _fitted(dissipative_folder, "lnn_dissipative")
    params = {**f.params, "dissipation.raw": np.full_like(np.asarray(f.params["dissipation.raw"]), OFF)}
    g = dataclasses.replace(f, params=params, model=Padded(adapter(f.framework, f.spec, params)))
    rows = _test_rows(dissipative_folder)
    out = Evaluation()
    out.metrics.update({"test_l1": without_dissipation_l1(f, rows), "null_test_l1": f.result["metrics"]["null_test_l1"]})
    dissipation_metrics(g, rows, "test", systems.get("pendulum"), out)
    assert out.metrics["test_dissipation_ablation"] == pytest.approx(1.0)
    assert out.metrics["test_dissipation_hessian_residual"] <= HESSIAN_RESIDUAL_MAX
    assert "test_dissipation_coefficient_0" not in out.metrics
    assert out.counters["test_dissipation_coefficient"].startswith("not estimated: the friction does not carry")


def _test_rows(folder):
    return user_data.rows(str(next(folder.glob("results/friction/data/test-*.csv"))), "test")   # as prepared


@pytest.mark.parametrize("kind", ["lnn_dissipative", "delan_dissipative"])
@pytest.mark.parametrize("scale", [0.0, 0.3, 3.0])
def test_rollouts_refuse_a_friction_the_data_do_not_single_out(request, kind, scale):
    """The fitted model with its coefficients removed, at 0.3 and at 3 times their learned values: each still
    learned (one-step) and keeps its velocity Hessian, but the test file's rollouts do not bracket its friction
    (removed: halving or doubling nothing changes nothing; too little: more rolls out better; too much: less
    does), so no friction is read, where the fit's own is (the tests above)."""
    folder = request.getfixturevalue("delan_folder" if kind == "delan_dissipative" else "dissipative_folder")
    f = _fitted(folder, kind)
    g = with_coefficients(f, scale * softplus(f.params["dissipation.raw"]))
    rows = _test_rows(folder)
    out = Evaluation()
    b, pred = g.one_step(rows)
    out.metrics.update({"test_l1": float(np.mean(np.sum(np.abs(pred - b["target"]), -1))),
                        "null_test_l1": f.result["metrics"]["null_test_l1"]})
    dissipation_metrics(g, rows, "test", systems.get("pendulum"), out, {"horizon": None, "substeps": 2})
    half, double = out.metrics["test_dissipation_bracket_half"], out.metrics["test_dissipation_bracket_double"]
    assert min(half, double) < BRACKET_MIN, (half, double)
    if scale == 0:
        assert half == pytest.approx(1.0) and double == pytest.approx(1.0)
    else:   # the side of the truth rolls out better
        assert (double if scale < 1 else half) < 1.0
    assert "test_dissipation_coefficient_0" not in out.metrics
    assert out.counters["test_dissipation_coefficient"].startswith("not estimated: the rollouts do not single out")
    own = Evaluation()   # the fit's own coefficients, through the same call: read
    own.metrics.update({k: f.result["metrics"][k] for k in ("test_l1", "null_test_l1")})
    dissipation_metrics(f, rows, "test", systems.get("pendulum"), own, {"horizon": None, "substeps": 2})
    assert own.metrics["test_dissipation_coefficient_0"] == pytest.approx(0.3, rel=0.1)


@pytest.mark.slow   # slow: two more fits and a report (about a minute on 2 cores)
def test_it_rolls_out_better_than_the_conservative_lnn(friction_folder):
    metrics = _metrics(friction_folder)
    d, lnn, base = metrics["lnn_dissipative"], metrics["lnn"], metrics["baseline"]
    assert "test_dissipation_coefficient_0" not in lnn
    assert d["test_rollout_gmean_err"] < 0.5 * lnn["test_rollout_gmean_err"]
    assert base["test_rollout_gmean_err"] < 0.5 * d["test_rollout_gmean_err"]   # as the doc's table says
    # the conservative LNN keeps the energy the pendulum loses
    assert lnn["test_energy_err_final"] > 5 * d["test_energy_err_final"]


@pytest.mark.parametrize("kind", ["lnn", "delan"])
def test_a_starved_fit_reports_no_friction(tmp_path, monkeypatch, kind):
    """Five steps: the model learned nothing, and its b / |c| (which can land anywhere) is not reported."""
    monkeypatch.chdir(tmp_path)
    for args in (["simulate", "--system", "pendulum", "--set", "friction=0.3", "--trajectories", "4", "--out", "d.csv"],
                 ["fit", "--data", "d.csv", "--model", kind, "--dissipation", "--system", "pendulum", "--steps", "5",
                  *(["--restarts", "0"] if kind == "lnn" else []), "--hidden", "16,16", "--out", "r", "--quiet"]):
        assert main(args) == 0
    d = json.loads(next(tmp_path.glob(f"r/units/fit/*/{kind}_dissipative/seed0/result.json")).read_text())
    assert not any(k.startswith("heldout_dissipation_coefficient") for k in d["metrics"])
    assert d["counters"]["heldout_dissipation_coefficient"] == ("not estimated: the model is not clearly better "
                                                                "than the null predictor")
