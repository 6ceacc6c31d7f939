"""`lagbench fit` trains with what the claims use against the plateau: restarts over initialisations (with
successive halving) and the gradient-spike guard, recorded in the fit's protocol; the LNN's and the baseline's by
default (the double-pendulum claims' protocol), off with 0."""
import pytest

from lagbench.cli import main
from lagbench.replication.fit import kind_defaults
from lagbench.replication.fit.task import fit


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    path = tmp_path_factory.mktemp("data") / "pendulum.csv"
    assert main(["simulate", "--system", "pendulum", "--trajectories", "4", "--duration", "3", "--rate", "20",
                 "--out", str(path)]) == 0
    return path


def test_restarts_and_the_guard_are_the_claims_protocol_parts(data, tmp_path):
    d = fit(data, model="lnn", out=tmp_path / "a", steps=6, hidden=(8,), batch=16, restarts=3, restart_steps=4,
            restart_keep=1, guard_clip=100.0, guard_skip=10.0)
    p = d["protocol"]
    assert p["scouting"]["count"] == 3 and p["scouting"]["steps"] == 4 and p["scouting"]["keep"] == 1
    ratio = kind_defaults.defaults("lnn", "acceleration")["restart_lr_ratio"]   # the restarts' peak follows --lr
    assert p["scouting"]["schedule"]["lr"] == pytest.approx(p["schedule"]["lr"] * ratio)
    assert p["guard"] == {"clip": 100.0, "skip": 10.0}
    assert len(d["scouting"]["init_seeds"]) == 3 and d["scouting"]["chosen"] in d["scouting"]["kept"]
    plain = fit(data, model="lnn", out=tmp_path / "b", steps=6, hidden=(8,), batch=16, restarts=0, guard_clip=0,
                guard_skip=0)
    assert plain["protocol"]["scouting"] is None and plain["protocol"]["guard"] is None


def test_bad_restart_options_are_named(data, tmp_path, capsys):
    for argv, words in ((["--restarts", "1"], "--restarts: 1 is not valid"),
                        (["--restarts", "0", "--restart-keep", "2"], "--restart-keep: 2 needs --restarts above it"),
                        (["--restarts", "2", "--restart-keep", "2"], "--restart-keep: 2 needs --restarts above it"),
                        (["--guard-clip", "-1"], "--guard-clip: -1.0 is not valid")):
        assert main(["fit", "--data", str(data), "--model", "lnn", "--steps", "2", *argv,
                     "--out", str(tmp_path / "x")]) == 2
        assert words in capsys.readouterr().err
    assert not (tmp_path / "x").exists() or not any((tmp_path / "x").glob("units/*"))
