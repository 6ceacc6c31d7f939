"""`--even-velocity auto` (`replication.fit.even_velocity`): an LNN that learns a dissipation on a noisy
recording gets a Lagrangian even in q-dot and half the default steps (the same network work), recorded in its
eval_config, its spec and its console line; a quiet recording, a conservative fit, another kind, given steps and
a given mode keep what they ask for."""
import json
import math

import pytest

from lagbench.cli import main
from lagbench.replication.fit import even_velocity, kind_defaults
from lagbench.replication.fit.resolve import resolved
from lagbench.replication.fit.task import fit


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("data")
    out = {}
    for noise in ("0.001", "0.01"):   # below and above the budget's switch (0.00172)
        out[noise] = folder / f"dp_{noise}.csv"
        assert main(["simulate", "--system", "double_pendulum", "--trajectories", "10", "--duration", "2", "--rate",
                     "100", "--noise", noise, "--set", "friction=0.2", "--seed", "3", "--out", str(out[noise])]) == 0
    return out


def _choice(path, dissipation, **options):
    r = resolved(path, {"model": "lnn", **options})
    r.options.dissipation = dissipation
    return even_velocity.for_fit(r.options, {"model": "lnn", **options}, r.task, r.recording, r.dof, r.noise)


def test_the_rule_in_every_case():
    assert even_velocity.choose("auto", "lnn", True, True)["chosen"]
    for args in (("auto", "lnn", False, True), ("auto", "lnn", True, False), ("auto", "hnn", True, True),
                 ("off", "lnn", True, True), (False, "lnn", True, True)):
        assert not even_velocity.choose(*args)["chosen"], args
    assert even_velocity.choose("on", "lnn", False, False) == {"mode": "on", "chosen": True, "why": "as given"}
    assert even_velocity.choose(True, "lnn", False, False)["chosen"]
    on = even_velocity.choose("auto", "lnn", True, True)
    assert even_velocity.steps_factor(on, True) == even_velocity.STEPS_FACTOR and even_velocity.steps_factor(on, False) == 1


def test_a_dissipative_lnn_on_a_noisy_recording_is_even_with_half_the_steps(files):
    claim = kind_defaults.defaults("lnn", "acceleration")
    o, record = _choice(files["0.01"], True)
    steps = math.ceil(claim["steps"] * even_velocity.STEPS_FACTOR)
    assert record["chosen"] and o.even_velocity is True and (o.steps, record["steps"]) == (steps, steps)
    # the restarts follow the halved steps, as they follow a given --steps; no fallback on a noisy file
    assert o.restart_steps == max(2, round(steps * claim["restart_fraction"])) and o.restart_fallback == 0
    assert o.restarts == claim["restarts"] and o.dissipation is True
    assert f"{steps} steps, {even_velocity.STEPS_FACTOR:g} x the plain LNN's" in even_velocity.describe(record)
    # conservative, quiet, given steps, given off: as asked
    o, record = _choice(files["0.01"], False)
    assert not record["chosen"] and o.even_velocity is False and o.steps == claim["steps"]
    o, record = _choice(files["0.001"], True)
    assert not record["chosen"] and o.steps == kind_defaults.ON_RECORDINGS[("lnn", "acceleration")] * claim["steps"]
    o, record = _choice(files["0.01"], True, steps=300)
    assert record["chosen"] and o.steps == 300 and "steps" not in record
    o, record = _choice(files["0.01"], True, even_velocity="off")
    assert not record["chosen"] and o.steps == claim["steps"]


def test_a_fit_records_the_choice_in_its_spec_config_and_console(files, tmp_path, capsys):
    out = tmp_path / "fit"
    assert main(["fit", "--data", str(files["0.01"]), "--model", "lnn", "--system", "double_pendulum", "--steps",
                 "20", "--restarts", "0", "--hidden", "16,16", "--quiet", "--out", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert "lagbench fit: Lagrangian even in q-dot: on (--even-velocity auto): an LNN learning a dissipation" in err
    result = json.loads(next(out.glob("units/fit/jax/lnn_dissipative/seed0/result.json")).read_text())
    assert result["model_spec"]["even_velocity"] is True
    assert result["eval_config"]["even_velocity"]["chosen"] is True
    d = fit(files["0.01"], out=tmp_path / "plain", model="lnn", system="double_pendulum", steps=20, restarts=0,
            hidden=(16, 16), even_velocity=False)
    assert "even_velocity" not in d["model_spec"] and "even_velocity" not in d["eval_config"]
