"""`lagbench fit --tune N`: the suite's declared search on a user's data, chosen on the training file's
held-out rows only (the test file is read by the final fit alone), the choice fitted again into OUT."""
import json

import pytest

from lagbench.cli import main
from lagbench.replication.fit import rows as fit_rows
from lagbench.replication.tuning import search


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("data")
    for name, seed in (("train", 0), ("test", 1)):
        assert main(["simulate", "--system", "spring", "--trajectories", "6", "--duration", "3", "--rate", "20",
                     "--noise", "0.0", "--seed", str(seed), "--out", str(d / f"{name}.csv")]) == 0
    return d / "train.csv", d / "test.csv"


def test_tune_chooses_on_heldout_rows_and_fits_the_choice_with_the_test_file(files, tmp_path, capsys, monkeypatch):
    train, test = files
    read = []
    real = fit_rows.prepare

    def prepare(out, path, *a, kind="train", **kw):
        read.append((kind, str(path)))
        return real(out, path, *a, kind=kind, **kw)
    monkeypatch.setattr(fit_rows, "prepare", prepare)
    out = tmp_path / "fit"
    assert main(["fit", "--data", str(train), "--test", str(test), "--model", "baseline", "--steps", "30",
                 "--hidden", "16", "--lr", "1e-3", "--quiet", "--tune", "3", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    ledger = json.loads((out / "tune" / "ledger.json").read_text())
    assert ledger["configs"] == search.configs(3)
    scores = {int(k): v for k, v in ledger["scores"].items()}
    assert ledger["chosen"] == min(scores, key=scores.get) and all(v is not None for v in scores.values())
    assert f"tune: chose configuration {ledger['chosen']} of 3" in printed
    tests = [i for i, (kind, _) in enumerate(read) if kind == "test"]
    assert len(tests) == 1 and tests[0] >= 3   # the test file: read once, by the final fit, after the three choices
    final = json.loads(next((out / "units" / "fit").rglob("result.json")).read_text())
    knobs = ledger["chosen_knobs"]
    assert final["protocol"]["schedule"]["lr"] == pytest.approx(1e-3 * knobs["lr"])
    assert final["model_spec"]["hidden"] == [max(1, round(16 * knobs["width"]))]


def test_tune_needs_heldout_rows_and_says_so_in_one_line(files, tmp_path, capsys):
    train, _ = files
    assert main(["fit", "--data", str(train), "--model", "baseline", "--steps", "5", "--quiet", "--tune", "2",
                 "--holdout", "none", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--tune" in err and "held-out" in err


def test_tune_refuses_a_count_outside_the_search(files, tmp_path, capsys):
    train, _ = files
    assert main(["fit", "--data", str(train), "--model", "baseline", "--steps", "5", "--quiet", "--tune",
                 str(search.SIZE + 1), "--out", str(tmp_path / "y")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--tune: {search.SIZE + 1} is not valid" in err
