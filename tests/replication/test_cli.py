"""The command line: help, list, and the duration estimate the paper profile prints."""
import pytest

from replication.cli import build_parser, main
from replication.runner import estimate_seconds, plan


def test_list_names_everything(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for word in ("double_pendulum", "lnn", "delan", "softplus", "cranmer2020", "quick", "dp_energy", "hnn_energy"):
        assert word in out


def test_help_describes_each_command(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["run", "--help"])
    out = capsys.readouterr().out
    for flag in ("--profile", "--claims", "--frameworks", "--seeds", "--out"):
        assert flag in out


def test_estimate_scales_measured_steps(tmp_path):
    units = plan("smoke", claims=["dp_loss"], frameworks=("jax",))
    est = estimate_seconds(units, tmp_path)
    assert est > 0 and est < 600
