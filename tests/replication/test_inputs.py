"""Bad input gets a clear error naming the problem: names, protocols, users' data files."""
import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.files import user_data
from lagbench.replication.fit.task import fit
from lagbench.replication.run.runner import plan
from lagbench.replication.training.protocol import Data, Protocol


@pytest.mark.parametrize("kwargs, words", [
    ({"profile": "huge"}, ["unknown profile", "quick"]),
    ({"profile": "smoke", "claims": ["nope"]}, ["unknown claim", "dp_loss"]),
    ({"profile": "smoke", "frameworks": ("mxnet",)}, ["unknown framework", "jax"]),
])
def test_unknown_names_list_valid_ones(kwargs, words):
    with pytest.raises((KeyError, ValueError)) as e:
        plan(**kwargs)
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize("field, value", [("loss", "huber"), ("schedule", "warm"), ("dtype", "float16"),
                                          ("steps", 0), ("batch", -1), ("schedule.lr", -1.0)])
def test_protocol_rejects_bad_fields(field, value):
    ok = Protocol(data=Data("spring_iid", n_train=16), steps=10, batch=4)
    with pytest.raises(ValueError, match=field if field != "schedule.lr" else "learning rate"):
        ok.replace(**{field: value})


def test_cli_reports_errors_without_a_traceback(capsys):
    assert main(["run", "--profile", "smoke", "--claims", "nope"]) == 2
    assert "unknown claim 'nope'" in capsys.readouterr().err


def _write(tmp_path, name, **cols):
    df = pd.DataFrame(cols)
    path = tmp_path / name
    df.to_csv(path, index=False)
    return path


def test_user_data_errors(tmp_path):
    rng = np.random.default_rng(0)
    ok = {k: rng.normal(size=40) for k in ("q0", "qdot0", "qddot0")}
    with pytest.raises(ValueError, match="no column t: .* or give qddot"):
        fit(_write(tmp_path, "a.csv", q0=ok["q0"], qdot0=ok["qdot0"]))
    nan = dict(ok, qddot0=np.where(np.arange(40) == 3, np.nan, ok["qddot0"]))
    with pytest.raises(ValueError, match="NaN"):
        fit(_write(tmp_path, "b.csv", **nan))
    (tmp_path / "c.txt").write_text("x")
    with pytest.raises(ValueError, match="unsupported file type"):
        fit(tmp_path / "c.txt")
    np.savez(tmp_path / "d.npz", q=np.zeros((30, 2)), qdot=np.zeros((29, 2)), qddot=np.zeros((30, 2)))
    with pytest.raises(ValueError, match="mismatched"):
        fit(tmp_path / "d.npz")
    (tmp_path / "e.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="cannot read"):
        user_data.load(str(tmp_path / "e.npz"))
    with pytest.raises(ValueError, match="--model"):
        fit(_write(tmp_path, "f.csv", **ok), model="gpt")


def test_fit_trains_on_a_user_file_in_both_frameworks(tmp_path):
    from lagbench import systems

    s = systems.get("pendulum")
    st = s.sample_states(400, np.random.default_rng(1))
    np.savez(tmp_path / "pend.npz", q=st["q"], qdot=st["qdot"], qddot=s.acceleration(st["q"], st["qdot"]))
    for fw in ("jax", "torch"):
        d = fit(tmp_path / "pend.npz", model="lnn", framework=fw, steps=30, hidden=(16, 16), out=tmp_path / "out")
        assert d["status"] == "ok" and np.isfinite(d["metrics"]["heldout_l1"])
    assert len(list((tmp_path / "out").glob("units/fit/*/lnn/seed0/result.json"))) == 2
