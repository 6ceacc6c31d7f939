"""The README's bring-your-own-data example, run from its own text in a fresh folder: two simulated files of
other seeds, a fit at its defaults, the evaluation on the test file written where the report reads, and the
report. The default run shortens the training (the README says so); the slow test runs the lines as written
and checks that the fit at its defaults learned (at most half the null predictor's one-step error on the test
file) and stopped early."""
import json
import re
import shlex
from pathlib import Path

import pytest

from lagbench.cli import main

ROOT = Path(__file__).resolve().parents[3]
MARKER = "<!-- bring-your-own-data example: tests/replication/fit/test_readme_data_example.py runs this block -->"
SHORT = {"fit": ["--steps", "40", "--hidden", "8", "--quiet"]}   # argparse takes the last of a repeated option


def example_commands() -> list[list[str]]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert MARKER in text, "README.md lost the bring-your-own-data example's marker"
    block = re.search(r"```bash\n(.*?)```", text[text.index(MARKER):], re.S).group(1)
    return [shlex.split(ln)[1:] for ln in block.splitlines() if ln.startswith("lagbench ")]


def _run(folder: Path, monkeypatch, short: bool) -> Path:
    monkeypatch.chdir(folder)
    commands = example_commands()
    assert [c[0] for c in commands] == ["simulate", "simulate", "fit", "evaluate", "report"]
    for args in commands:
        args = [*args, *SHORT.get(args[0], [])] if short else args
        assert main(args) == 0, args
    return folder


def _results(folder: Path) -> dict:
    out = {}
    for path in folder.glob("results/byod/units/*/*/*/seed0/result.json"):
        d = json.loads(path.read_text())
        out[d["claim"]] = d
    return out


def test_the_readme_data_example_runs_and_the_report_shows_the_evaluation(tmp_path, monkeypatch):
    folder = _run(tmp_path, monkeypatch, short=True)
    train, test = (folder / "data" / "train.csv").read_bytes(), (folder / "data" / "test.csv").read_bytes()
    assert train != test, "the test file must hold other trajectories than the training file"
    results = _results(folder)
    assert set(results) == {"fit", "evaluate"}, "the evaluation must land in the folder the report reads"
    assert results["evaluate"]["metrics"]["test_l1"] > 0
    report = next(folder.glob("report/byod/REPORT.md")).read_text(encoding="utf-8")
    assert "evaluate" in report.lower()


@pytest.mark.slow
def test_the_readme_data_example_as_written_learns_and_stops_early(tmp_path, monkeypatch):
    results = _results(_run(tmp_path, monkeypatch, short=False))
    judged = results["evaluate"]["metrics"]
    assert judged["test_l1"] < 0.5 * judged["null_test_l1"]
    assert results["fit"]["early_stop"]["stopped_at"] is not None
