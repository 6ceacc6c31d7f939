"""`lagbench fit`'s choices from the data and the system: `--dissipation auto` (on where the training trajectories
lose energy by the true energy function: `replication.fit.energy_trend`) and `--periodic auto` (the coordinates in
which the system's Lagrangian is 2 pi-periodic: `replication.fit.periodic_coords`), parsed, recorded, printed and
reported."""
import json
import re
from types import SimpleNamespace

import numpy as np
import pytest

from lagbench import systems
from lagbench.cli import build_parser, main
from lagbench.files import user_data
from lagbench.files.results import write_csv
from lagbench.replication.fit import energy_trend, periodic_coords, trajectories
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit.simulate import simulate
from lagbench.reports.fit_paragraphs import choices_para as _choices_para

# (system, trajectories, duration, rate): small files of the recordings the rule was calibrated on
RECORDINGS = {"pendulum": (3, 5.0, 50.0), "double_pendulum": (3, 4.0, 100.0)}


def _rows(tmp_path, system, friction, noise, seed=0):
    """The rows a fit prepares from a `lagbench simulate` file (2 % of frames dropped), at `--window auto`."""
    n, duration, rate = RECORDINGS[system]
    path = str(tmp_path / f"{system}_{friction}_{noise}.csv")
    write_csv(path, simulate(system, n, duration, rate, noise, seed, dropped=0.02, decimals=6,
                             settings=[f"friction={friction}"]))
    _, d = user_data.read(path)
    return trajectories.with_derivatives(d, path, trajectories.derivative_record(d, path, "auto")["window"])


@pytest.mark.parametrize("system", sorted(RECORDINGS))
@pytest.mark.parametrize("friction, noise, loses", [(0.0, 0.001, False), (0.0, 0.0087, False), (0.05, 0.0087, True),
                                                    (0.2, 0.0087, True)])
def test_the_energy_rule_tells_friction_from_noise(tmp_path, system, friction, noise, loses):
    energy = systems.get(system).energy
    rows = _rows(tmp_path, system, friction, noise)
    record = energy_trend.choose("auto", True, rows, energy)
    assert record["chosen"] is loses, record
    assert record["trajectories"] == RECORDINGS[system][0]
    assert (record["median"] < -energy_trend.DROP) is loses
    # E's zero is arbitrary: a constant added to the energy reads the same
    shifted = energy_trend.measure(rows, lambda q, qd: energy(q, qd) - 50.0)
    np.testing.assert_allclose(shifted.relative, energy_trend.measure(rows, energy).relative, rtol=1e-9)


def test_a_median_drop_without_a_majority_losing_is_not_friction():
    half = energy_trend.Trend(np.array([-0.5, -0.4, 0.01, 0.02, -0.2, 0.03]), 6)   # median -0.095, half losing
    assert half.median < -energy_trend.DROP and half.losing < energy_trend.MAJORITY
    assert energy_trend.decide(half)[0] is False
    assert energy_trend.decide(energy_trend.Trend(half.relative - 0.1, 6))[0] is True   # 5 of 6 losing


def test_without_an_energy_function_or_trajectories_auto_is_off():
    assert energy_trend.choose("auto", True, None, None) == {"mode": "auto", "chosen": False,
                                                            "why": energy_trend.NO_ENERGY}
    assert energy_trend.choose("auto", True, None, np.sum)["chosen"] is False          # a state file
    assert energy_trend.choose("auto", False, None, np.sum)["why"].startswith("the model kind has no dissipation")
    assert energy_trend.choose("auto", True, {}, np.sum, forced=True)["why"].startswith("the data hold torques")
    assert energy_trend.choose(True, True)["chosen"] is True and energy_trend.choose("off", True)["chosen"] is False


@pytest.mark.parametrize("system, periodic", [("pendulum", (0,)), ("double_pendulum", (0, 1)),
                                              ("pendulum_chain", (0, 1, 2)), ("two_link_arm", (0, 1)),
                                              ("four_joint_arm", (1, 2, 3)), ("spring", ()), ("free_fall", ()),
                                              ("charged_magnetic", ()), ("relativistic", ())])
def test_the_periodic_coordinates_are_read_off_the_lagrangian(system, periodic):
    assert periodic_coords.periodic_in(system) == periodic


def test_periodic_auto_needs_a_system_and_no_angle_wrap():
    assert periodic_coords.choose("auto", "double_pendulum", False)["chosen"] == [0, 1]
    assert periodic_coords.choose("auto", "double_pendulum", True)["chosen"] == []
    assert periodic_coords.choose("auto", None, False)["chosen"] == []
    assert periodic_coords.choose("auto", "spring", False)["chosen"] == []
    assert periodic_coords.choose((1,), None, False) == {"mode": "1", "chosen": [1], "why": "as given"}


def _parsed(*flags) -> dict:
    return fit_options.resolve(fit_options.from_args(build_parser().parse_args(["fit", "--data", "d.csv", *flags])))


def test_the_flags_parse():
    assert (_parsed("--model", "lnn").dissipation, _parsed("--model", "lnn").periodic) == ("auto", "auto")
    assert _parsed("--dissipation", "--model", "lnn").dissipation == "on"   # the flag alone, as it always was
    assert _parsed("--model", "lnn", "--dissipation").dissipation == "on"
    assert _parsed("--model", "lnn", "--dissipation", "off").dissipation == "off"
    assert _parsed("--model", "lnn", "--periodic", "none").periodic == ()
    assert _parsed("--model", "lnn", "--periodic", "0,1").periodic == (0, 1)
    assert fit_options.resolve({"model": "lnn", "dissipation": False}).dissipation == "off"


@pytest.mark.parametrize("flags, match", [(["--dissipation", "maybe"], "--dissipation: 'maybe' is not valid; "
                                           "expected one of auto, on, off"),
                                          (["--model", "baseline", "--dissipation"], "--dissipation: for --model lnn"),
                                          (["--periodic", "0", "--angle-wrap"], "--periodic: .*angle_wrap"),
                                          (["--system", "double_pendulum"], "--system double_pendulum: has 2 "
                                           "coordinates, the data .* 1")])
def test_a_bad_value_is_one_line_naming_the_option(tmp_path, capsys, flags, match):
    path = tmp_path / "d.csv"
    write_csv(path, simulate("pendulum", 2, 1.0, 50.0, 0.001, 0))
    args = ["fit", "--data", str(path), "--model", "lnn", *flags, "--out", str(tmp_path / "o")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert re.search(match, err), err
    assert not (tmp_path / "o" / "data").exists()


def test_a_fit_records_prints_and_reports_its_choices(tmp_path, capsys):
    path = tmp_path / "friction.csv"
    write_csv(path, simulate("pendulum", 4, 2.0, 50.0, 0.001, 0, settings=["friction=0.2"]))
    assert main(["fit", "--data", str(path), "--model", "lnn", "--system", "pendulum", "--steps", "5",
                 "--restarts", "0", "--hidden", "8", "--horizon", "0.2", "--framework", "torch", "--out", str(tmp_path / "o"),
                 "--quiet"]) == 0
    out = capsys.readouterr()
    lines = [ln for ln in out.err.splitlines() if ln.startswith("lagbench fit: ")]
    assert "lagbench fit: periodic inputs: q0 (--periodic auto: the Lagrangian of pendulum is 2 pi-periodic in it)" \
        in lines
    said = next(ln for ln in lines if ln.startswith("lagbench fit: dissipation: "))
    assert said.startswith("lagbench fit: dissipation: on (--dissipation auto): the training data lose energy")
    folder = tmp_path / "o" / "units" / "fit" / "torch" / "lnn_dissipative" / "seed0"   # the form chosen, its folder
    assert str(folder) in out.out
    d = json.loads((folder / "result.json").read_text())
    cfg = d["eval_config"]
    assert cfg["periodic"]["chosen"] == [0] and d["model_spec"]["periodic"] == [0]
    assert cfg["dissipation"]["chosen"] is True and d["model_spec"]["dissipation"] is True
    assert cfg["dissipation"]["median"] < -energy_trend.DROP and cfg["dissipation"]["losing"] == 1.0
    unit = SimpleNamespace(result=d, claim="fit", model="lnn_dissipative", framework="torch", seed=0)
    text = _choices_para([unit]).text
    assert "periodic inputs q0 (--periodic auto" in text and "dissipation on (--dissipation auto)" in text
