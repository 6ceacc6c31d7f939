"""The worked example (docs/fit.md) of bringing your own data (issue 26), run end to end from its own text:
the `lagbench` lines of the block after the marker, in a fresh folder. The default run shrinks the
training (steps, widths, trajectories) to seconds; the slow test runs the block as written and checks
what the page says of its results."""
import json
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from lagbench.cli import main
from lagbench.replication.fit.load import load_fitted

README = Path(__file__).resolve().parents[3] / "docs" / "fit.md"
MARKER = "<!-- worked example: tests/replication/fit/test_fit_example.py runs this block -->"
# the default run's smaller example (argparse takes the last of a repeated option)
SMALL = {"simulate": ["--trajectories", "3", "--duration", "1.2"], "fit": ["--steps", "10", "--hidden", "8"]}


def example_commands() -> list[list[str]]:
    text = README.read_text(encoding="utf-8")
    assert MARKER in text, "docs/fit.md lost the worked example's marker"
    block = re.search(r"```bash\n(.*?)```", text[text.index(MARKER):], re.S).group(1)
    lines = [ln.split("  #")[0].strip() for ln in block.splitlines()]
    return [shlex.split(ln)[1:] for ln in lines if ln.startswith("lagbench ")]


def shrink(args: list[str]) -> list[str]:
    return [*args, *SMALL.get(args[0], [])]


def _run(tmp_path, monkeypatch, small: bool, capsys=None) -> dict:
    monkeypatch.chdir(tmp_path)
    commands = example_commands()
    assert [c[0] for c in commands] == ["simulate", "simulate", "fit", "fit", "evaluate", "report"]
    for args in commands:
        args = shrink(args) if small else args
        assert main(args if args[0] != "fit" else [*args, "--quiet"]) == 0, args
        printed = capsys.readouterr().out if capsys is not None else None
        if args[0] == "fit" and printed is not None:  # the metric printed is named for the loss and the rows
            assert printed.startswith(("ok: test L1 ", "done: test L1 ")) and "null predictor" in printed, printed
    out = {}
    for path in tmp_path.glob("results/*/units/*/*/*/seed0/result.json"):
        d = json.loads(path.read_text())
        out[(d["claim"], d["framework"], d["model"])] = d["metrics"]
    return out


def test_the_worked_example_runs_end_to_end(tmp_path, monkeypatch, capsys):
    metrics = _run(tmp_path, monkeypatch, small=True, capsys=capsys)
    assert set(metrics) == {("fit", "jax", "lnn"), ("fit", "jax", "baseline"), ("evaluate", "torch", "lnn"),
                            ("evaluate", "torch", "baseline")}
    for model in ("lnn", "baseline"):
        fitted, judged = metrics[("fit", "jax", model)], metrics[("evaluate", "torch", model)]
        assert {"test_l1", "test_rollout_gmean_err", "test_energy_err_final", "test_vpt_s"} <= set(judged)
        assert 0 <= judged["test_vpt_s"] and judged["test_vpt_nmse_s"] <= judged["test_vpt_s"]
        # the model trained in JAX, loaded in PyTorch, judged on the same test file: the same one-step numbers
        # (an untrained model's rollouts may blow up, where float32 differences grow without bound)
        assert judged["test_l1"] == pytest.approx(fitted["test_l1"], rel=1e-4)
    assert "test_learned_energy_drift" in metrics[("fit", "jax", "lnn")]
    with pytest.raises(ValueError, match="2 fitted models"):
        load_fitted(tmp_path / "results/byod")
    with pytest.raises(ValueError, match="trained on accelerations"):
        load_fitted(tmp_path / "results/byod/units/fit/jax/lnn/seed0").inverse_dynamics(*[np.zeros((1, 1))] * 3)
    report = next(tmp_path.glob("report/*/REPORT.md")).read_text()
    assert "The models side by side" in report and "Rollouts and energy" in report
    assert "Findings" not in report and "Claim " not in report and "weight decay kept" not in report
    assert len(list(tmp_path.glob("report/*/figures/fit_*.png"))) >= 4


@pytest.mark.slow
def test_the_worked_example_as_written_gives_what_the_readme_says(tmp_path, monkeypatch):
    metrics = _run(tmp_path, monkeypatch, small=False)
    lnn, base = metrics[("fit", "jax", "lnn")], metrics[("fit", "jax", "baseline")]
    # about as near the true energy at the end, as the page says
    assert lnn["test_energy_err_final"] < 1.5 * base["test_energy_err_final"]
    assert base["test_energy_err_final"] < 1.5 * lnn["test_energy_err_final"]
    assert lnn["test_rollout_gmean_err"] < 1.5 * base["test_rollout_gmean_err"]   # about equal, as the page says
    assert lnn["test_l1"] < lnn["null_test_l1"] / 2 and base["test_l1"] < base["null_test_l1"] / 2
    assert lnn["test_learned_energy_drift"] < 1e-4 * lnn["test_energy_err_final"]  # RK4 keeps its own energy
