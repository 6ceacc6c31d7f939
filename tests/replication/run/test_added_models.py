"""`lagbench run --add-model` (`replication.run.added_models`, `models.user`): which claims a user's model
enters and with what, what it is refused with, and that an edited model file is a new spec."""
import numpy as np
import pytest

from models import ModelSpec, init_params
from replication.claims import CLAIMS
from replication.claims.bars import Bar, added_competence
from replication.claims.stats import Stat
from replication.evaluation.adapters import adapter
from replication.run import added_models
from replication.run.runner import plan

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
    assert e.protocol(dp.protocol("quick"), "quick") == dp.entry("lnn").protocol(dp.protocol("quick"), "quick")
    hnn = CLAIMS["hnn_energy"]
    assert sorted(x.label for x in added_models.entries(hnn, a, "quick")) == ["mine_pendulum", "mine_spring"]
    # not where the paper models see an extra input (the field g), predict torques, or are graph networks
    table1 = sorted(x.label for x in added_models.entries(CLAIMS["delan_table1"], a, "quick"))
    assert table1 == ["mine_charged_magnetic", "mine_relativistic"]
    for cid in ("rel_coords", "delan_arm", "wave_lgn", "init_study"):
        assert added_models.entries(CLAIMS[cid], a, "quick") == [], cid


def test_it_runs_in_pytorch_alone(model_file):
    (a,) = added_models.parse([f"mine={model_file}:make"])
    units = plan("smoke", claims=["dp_loss"], frameworks=("jax", "torch"), added=[a])
    assert {u.framework for u in units if u.entry.label == "mine"} == {"torch"}
    assert {u.framework for u in units if u.entry.label == "lnn"} == {"jax", "torch"}
    with pytest.raises(ValueError, match="runs in PyTorch"):
        plan("smoke", claims=["dp_loss"], frameworks=("jax",), added=[a])


@pytest.mark.parametrize("value, message", [
    ("mine", "give NAME=module:factory"), ("1st={f}:make", "give NAME=module:factory"),
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
    with pytest.raises(ValueError, match="needs a factory"):
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
    v = {"lnn": {"heldout_l1": Stat.of([1.0]), "null_heldout_l1": Stat.of([50.0])},
         "mine": {"heldout_l1": Stat.of([40.0]), "null_heldout_l1": Stat.of([50.0])}}
    per = added_competence(bars, v, {"lnn"})
    assert set(per) == {"mine"} and per["mine"][0] is False and "40 > 0.1 x null 50" in per["mine"][1]
