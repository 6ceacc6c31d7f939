"""`lagbench run --add-model` (`replication.run.added_models`, `models.user`): which claims a user's model
enters and with what, what it is refused with, and that an edited model file is a new spec."""
import json
import re

import numpy as np
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.files.user_functions import NO_RERUN, UserCodeError
from lagbench.models import ModelSpec, init_params
from lagbench.replication.claims import CLAIMS
from lagbench.replication.claims.bars import Bar, added_competence
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.run import added_models
from lagbench.replication.run.runner import plan

MODEL = '''import torch


class Net(torch.nn.Module):
    def __init__(self, dof):
        super().__init__()
        self.lin = torch.nn.Linear(2 * dof, dof)

    def forward(self, q, qdot):
        return self.lin(torch.cat([q, qdot], -1)){tail}


def make(dof):
    return Net(dof)


def not_a_module(dof):
    return 3
'''


@pytest.fixture
def model_file(tmp_path):
    path = tmp_path / "user_net.py"
    path.write_text(MODEL.format(tail=""), encoding="utf-8")
    return path


def test_the_model_enters_each_claim_it_fits_once_per_system_with_the_paper_models_protocol(model_file):
    (a,) = added_models.parse([f"mine={model_file}:make"])
    dp = CLAIMS["dp_loss"]
    (e,) = added_models.entries(dp, a, "quick")
    assert e.label == "mine" and e.spec["kind"] == "user"
    # the LNN's protocol as it runs (`claims.resolved`: the adopted tuning applied)
    assert e.protocol(dp.protocol("quick"), "quick") == resolved(dp, "quick").model("lnn").protocol
    hnn = CLAIMS["hnn_energy"]
    assert sorted(x.label for x in added_models.entries(hnn, a, "quick")) == ["mine_pendulum", "mine_spring"]
    # not where the paper models see an extra input (the field g), predict torques, or are graph networks
    table1 = sorted(x.label for x in added_models.entries(CLAIMS["delan_table1"], a, "quick"))
    assert table1 == ["mine_charged_magnetic", "mine_relativistic"]
    for cid in ("rel_coords", "delan_arm", "wave_lgn", "init_study"):
        assert added_models.entries(CLAIMS[cid], a, "quick") == [], cid


def test_a_pytorch_model_joins_quicks_jax_run_in_its_own_framework(model_file):
    # quick trains the paper's models in JAX alone unless frameworks are named; the user's module in PyTorch
    (a,) = added_models.parse([f"mine={model_file}:make"])
    units = plan("quick", claims=["hnn_energy"], added=[a])
    assert {(u.entry.label.startswith("mine"), u.framework) for u in units} == {(False, "jax"), (True, "torch")}
    with pytest.raises(ValueError, match="add torch to --frameworks"):   # named frameworks must include it
        plan("quick", claims=["hnn_energy"], frameworks=("jax",), added=[a])


def test_it_runs_in_pytorch_alone(model_file):
    (a,) = added_models.parse([f"mine={model_file}:make"])
    units = plan("smoke", claims=["dp_loss"], frameworks=("jax", "torch"), added=[a])
    assert {u.framework for u in units if u.entry.label == "mine"} == {"torch"}
    assert {u.framework for u in units if u.entry.label == "lnn"} == {"jax", "torch"}
    with pytest.raises(ValueError, match="runs in torch"):
        plan("smoke", claims=["dp_loss"], frameworks=("jax",), added=[a])


@pytest.mark.parametrize("value, message", [
    ("mine", "no installed package declares it"), ("mine=", "give NAME=module:factory"), ("1st={f}:make", "give NAME=module:factory"),
    ("lnn={f}:make", "is taken"), ("mine={f}:nothing", "cannot import"), ("mine=no_such_module:make", "cannot import"),
])
def test_a_bad_option_is_one_clear_error(model_file, value, message):
    with pytest.raises(ValueError, match=message):
        added_models.parse([value.format(f=model_file)], {"lnn"})


def test_a_factory_that_returns_no_module_is_refused_when_built(model_file):
    spec = ModelSpec(kind="user", dof=2, factory=f"{model_file}:not_a_module", factory_source="0" * 16)
    with pytest.raises(ValueError, match="not a torch.nn.Module"):
        init_params(spec, 0)
    with pytest.raises(ValueError, match="needs a factory"):
        ModelSpec(kind="user", dof=2)
    with pytest.raises(ValueError, match="factory is for kind user, not 'lnn'"):
        ModelSpec(kind="lnn", dof=2, factory="x:y")


def test_an_edited_model_file_is_a_new_spec_and_the_same_seed_the_same_numbers(model_file):
    (a,) = added_models.parse([f"mine={model_file}:make"])
    model_file.write_text(MODEL.format(tail=" * 2"), encoding="utf-8")
    (b,) = added_models.parse([f"mine={model_file}:make"])
    assert a.source != b.source   # a cached training keyed on the spec is never reused for the edited model
    spec = ModelSpec(kind="user", dof=2, factory=b.ref, factory_source=b.source, dtype="float64")
    p0, p1 = init_params(spec, 3), init_params(spec, 3)
    assert all(np.array_equal(p0[k], p1[k]) for k in p0) and set(p0) == {"lin.weight", "lin.bias"}
    m = adapter("torch", spec, p0)
    q, qd = np.ones((4, 2)), np.zeros((4, 2))
    np.testing.assert_allclose(m.acceleration(q, qd, None), 2 * (q @ p0["lin.weight"][:, :2].T + p0["lin.bias"]))


def test_the_added_model_is_held_to_the_claims_first_bar():
    bars = (Bar(("lnn",), "heldout_l1"),)
    v = {"lnn": [{"seed": 0, "status": "ok", "heldout_l1": 1.0, "null_heldout_l1": 50.0}],
         "mine": [{"seed": 0, "status": "ok", "heldout_l1": 40.0, "null_heldout_l1": 50.0}]}
    per = added_competence(bars, v, {"lnn"})
    assert set(per) == {"mine"} and per["mine"][0] is False and "40 > 0.1 x null 50" in per["mine"][1]


def test_an_installed_package_declares_its_model_by_entry_point(model_file, monkeypatch):
    import importlib.metadata
    from importlib.metadata import EntryPoint

    monkeypatch.syspath_prepend(str(model_file.parent))
    eps = [EntryPoint("theirs", "user_net:make", added_models.GROUP)]
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group=None: [e for e in eps if e.group == group])
    (a,) = added_models.parse(["theirs"])
    assert (a.name, a.ref) == ("theirs", "user_net:make") and len(a.source) == 16
    with pytest.raises(ValueError, match="installed: theirs"):
        added_models.parse(["other"])


TORCH_SCALAR = '''import torch


class S(torch.nn.Module):
    returns = "{returns}"

    def __init__(self, dof):
        super().__init__()
        self.k = torch.nn.Parameter(torch.tensor([2.0]))

    def forward(self, q, v):
        return 0.5 * (v ** 2).sum(-1) {sign} 0.5 * self.k * (q ** 2).sum(-1)


def make(dof):
    return S(dof)
'''
LAGRANGIAN = TORCH_SCALAR.format(returns="lagrangian", sign="-")   # L = |qdot|^2 / 2 - k |q|^2 / 2
HAMILTONIAN = TORCH_SCALAR.format(returns="hamiltonian", sign="+")   # H = |p|^2 / 2 + k |q|^2 / 2
EQX_LAGRANGIAN = '''import equinox as eqx
import jax.numpy as jnp


class L(eqx.Module):
    returns = "lagrangian"
    k: jnp.ndarray

    def __init__(self, dof, key):
        self.k = jnp.array([2.0])

    def __call__(self, q, qdot):
        return 0.5 * (qdot ** 2).sum(-1) - 0.5 * self.k[0] * (q ** 2).sum(-1)


def make(dof, key):
    return L(dof, key)
'''


def _added(tmp_path, text, name):
    path = tmp_path / f"user_{name}.py"
    path.write_text(text, encoding="utf-8")
    (a,) = added_models.parse([f"{name}={path}:make"])
    return a, ModelSpec(kind="user", dof=1, factory=a.ref, factory_source=a.source, dtype="float64")


def _learns_the_springs_k(framework, spec, key, **protocol):
    """Trained on the spring (k = 1) with restarts over initialisations (the scouts train as members), the
    module's k (2 at the start) comes within 5 % of the spring's."""
    from lagbench.replication.training.protocol import Data, Protocol, Scouting
    from lagbench.replication.training.schedules import OneCycle
    from lagbench.replication.training.train import run_training

    coords = {"coords": "qp"} if protocol.get("task") == "hamiltonian" else {}
    p = Protocol(data=Data("spring_iid", n_train=256, n_heldout=64, **coords), steps=150, batch=32, loss="mse",
                 schedule=OneCycle(lr=3e-2, start=0.3), log_every=50, dtype="float64",
                 scouting=Scouting(count=2, steps=20, batch=32, schedule=OneCycle(lr=3e-2, start=0.3)), **protocol)
    out = run_training(framework, spec, p, seed=0)
    k_true = -float(systems.get("spring").acceleration(np.ones((1, 1)), np.zeros((1, 1)))[0, 0])
    assert out.failure is None and abs(float(out.params[key][0]) - k_true) < 0.05 * k_true


@pytest.mark.parametrize("framework, text, key", [("torch", LAGRANGIAN, "k"), ("jax", EQX_LAGRANGIAN, ".k")])
def test_a_lagrangian_module_trains_in_its_framework_through_the_suites_euler_lagrange_step(tmp_path, framework,
                                                                                           text, key):
    """L = |qdot|^2 / 2 - k |q|^2 / 2 gives qddot = -k q; a torch module trains in PyTorch, an equinox one in JAX."""
    a, spec = _added(tmp_path, text, "lag")
    assert a.framework == framework and set(init_params(spec, 0)) == {key}
    units = plan("smoke", claims=["dp_loss"], frameworks=("jax", "torch"), added=[a])
    assert {u.framework for u in units if u.entry.label == "lag"} == {framework}
    q, qd = np.random.default_rng(0).normal(size=(5, 1)), np.ones((5, 1))
    np.testing.assert_allclose(adapter(framework, spec, init_params(spec, 0)).acceleration(q, qd, None), -2.0 * q,
                               atol=1e-12)
    _learns_the_springs_k(framework, spec, key)


def test_a_hamiltonian_module_stands_in_for_the_hnn_and_goes_through_hamiltons_equations(tmp_path):
    a, spec = _added(tmp_path, HAMILTONIAN, "ham")
    assert a.returns == "hamiltonian"
    hnn = CLAIMS["hnn_energy"]
    entries = added_models.entries(hnn, a, "quick")
    assert sorted(e.label for e in entries) == ["ham_pendulum", "ham_spring"]
    for e in entries:   # on the HNN's data and task, not the baseline's
        assert e.protocol(hnn.protocol("quick"), "quick").task == "hamiltonian"
    assert added_models.entries(CLAIMS["dp_loss"], a, "quick") == []   # no HNN there
    x, y = np.random.default_rng(0).normal(size=(2, 5, 1))
    xdot, ydot = adapter("torch", spec, init_params(spec, 0)).time_derivative(x, y, None)
    np.testing.assert_allclose(xdot, y, atol=1e-12)
    np.testing.assert_allclose(ydot, -2.0 * x, atol=1e-12)
    _learns_the_springs_k("torch", spec, "k", task="hamiltonian")


BROKEN = '''import equinox as eqx
import jax.numpy as jnp
import torch


class Boom(torch.nn.Module):
    def __init__(self, dof):
        super().__init__()
        raise RuntimeError("no weights here")


class Net(torch.nn.Module):
    def __init__(self, dof, extra=0, fail=False):
        super().__init__()
        self.lin, self.fail = torch.nn.Linear(2 * dof, dof + extra), fail

    def forward(self, q, qdot):
        if self.fail:
            raise RuntimeError("forward broke")
        out = self.lin(torch.cat([q, qdot], -1))
        if q.shape[0] > 64:   # the held-out set, never a training batch: NaN on every seventh state
            rows = torch.arange(q.shape[0], device=q.device)[:, None]
            out = torch.where(rows % 7 == 0, torch.full_like(out, float("nan")), out)
        return out


class Eqx(eqx.Module):
    k: jnp.ndarray

    def __init__(self, dof, key):
        self.k = jnp.ones(dof)

    def __call__(self, q, qdot):
        return q.reshape(-1)   # the wrong shape


def boom(dof):
    return Boom(dof)


def wide(dof):
    return Net(dof, extra=1)


def raises(dof):
    return Net(dof, fail=True)


def nan_held_out(dof):
    return Net(dof)


def eqx_flat(dof, key):
    return Eqx(dof, key)
'''


@pytest.fixture
def broken(tmp_path, monkeypatch):
    (tmp_path / "broken_net.py").write_text(BROKEN, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_a_factory_that_raises_is_one_line_naming_its_file_and_v_shows_the_users_traceback(broken, capsys):
    argv = ["run", "--profile", "smoke", "--claims", "dp_loss", "--add-model", "b=broken_net.py:boom", "--dry-run",
            "--out", str(broken / "res")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert ("--add-model broken_net.py:boom: the factory boom(dof) raised RuntimeError: no weights here "
            "(broken_net.py line 9, in __init__); an error in your code: a rerun fails the same way") in err
    assert main(["-v", *argv]) == 2
    err = capsys.readouterr().err
    shown = err.split("Traceback (your code):", 1)[1]
    assert 'broken_net.py", line 38, in boom' in shown and "replication" not in shown.split("lagbench: error")[0]


@pytest.mark.parametrize("factory, words", [
    ("raises", "Net.forward(q, qdot) raised RuntimeError: forward broke (broken_net.py line 19, in forward)"),
    ("wide", "forward(q, qdot) returned shape (4, 3), expected (4, 2)"),
    ("eqx_flat", "forward(q, qdot) returned shape (8,), expected (4, 2)"),
])
def test_a_forward_that_raises_or_returns_the_wrong_shape_is_the_users_error(broken, factory, words):
    (a,) = added_models.parse([f"x=broken_net.py:{factory}"])
    spec = ModelSpec(kind="user", dof=2, factory=a.ref, factory_source=a.source, dtype="float64")
    with pytest.raises(UserCodeError) as e:
        adapter(a.framework, spec, init_params(spec, 0)).acceleration(np.ones((4, 2)), np.zeros((4, 2)), None)
    assert words in str(e.value) and str(e.value).endswith("a rerun fails the same way until it is fixed")


def test_a_run_says_once_that_a_rerun_cannot_help_and_a_non_finite_model_fails(broken, capsys):
    """One unit's forward returns the wrong shape (an error: no result, exit 2, no traceback, and no "a rerun
    retries it"); the other's is NaN on held-out states (a result: failed, never ok). Only the claim named is
    listed."""
    out = broken / "res"
    argv = ["run", "--profile", "smoke", "--claims", "dp_loss", "--add-model", "w=broken_net.py:wide",
            "--add-model", "n=broken_net.py:nan_held_out", "--models", "w,n", "--quiet", "--out", str(out)]
    assert main(argv) == 2
    std = capsys.readouterr()
    assert [line.split()[0] for line in std.out.splitlines()] == ["dp_loss"]
    (line,) = std.err.splitlines()
    assert line.startswith("lagbench: error in unit dp_loss/torch/w/seed1000: --add-model broken_net.py:wide: "
                           "forward(q, qdot) returned shape (16, 3), expected (16, 2)")
    assert line.endswith("a rerun fails the same way until it is fixed")
    (result,) = (out / "units" / "dp_loss" / "torch" / "n").glob("seed*/result.json")
    d = json.loads(result.read_text())
    assert d["status"] == "failed" and d["failure"]["kind"] == "non_finite_prediction"
    assert re.fullmatch(r"non-finite on (\d+) of (\d+) held-out states", d["failure"]["message"])


def test_unit_errors_are_printed_once_per_message_with_the_exit_status_they_call_for(capsys):
    from lagbench.cli import _print_errors

    mine = "--add-model m.py:f: the factory f(dof) raised KeyError: 'a' (m.py line 2, in f); " + NO_RERUN
    assert _print_errors([f"a/torch/m/seed1: {mine}", f"b/torch/m/seed1: {mine}", "c/jax/lnn/seed1: OSError: gone"]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines == [f"lagbench: error in 2 units (a/torch/m/seed1, b/torch/m/seed1): {mine}",
                     "lagbench: error in unit c/jax/lnn/seed1: OSError: gone (no result written; a rerun retries it)"]
    assert _print_errors(["c/jax/lnn/seed1: OSError: gone"]) == 1 and _print_errors([]) == 0
