"""Every fit and evaluation says whether its model learned: the error beside the null predictor's and their
ratio, a flag when it is not clearly better (`replication.fit.competence`), exit status 1 only with --strict."""
import pytest

from lagbench.cli import main
from lagbench.replication.fit.competence import FACTOR, competence


def test_the_ratio_decides_and_a_missing_null_gives_nothing():
    assert competence({"test_l1": 1.0, "null_test_l1": 10.0}, "test_l1")["learned"]
    assert competence({"test_l1": 0.8, "null_test_l1": 1.0}, "test_l1")["verdict"].startswith("not clearly better")
    assert competence({"test_l1": 1.4, "null_test_l1": 1.0}, "test_l1")["verdict"].startswith("no better")
    assert competence({"test_l1": FACTOR, "null_test_l1": 1.0}, "test_l1")["learned"]
    assert competence({"test_l1": 1.0}, "test_l1") is None and competence({}, "final_train_loss") is None


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    path = tmp_path_factory.mktemp("data") / "spring.csv"
    assert main(["simulate", "--system", "spring", "--trajectories", "8", "--duration", "4", "--rate", "20",
                 "--noise", "0.0", "--out", str(path)]) == 0
    return path


def test_a_starved_fit_is_flagged_and_strict_fails_it(data, tmp_path, capsys):
    argv = ["fit", "--data", str(data), "--model", "baseline", "--steps", "1", "--restarts", "0", "--hidden", "8",
            "--quiet"]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("done: ") and "BETTER THAN THE NULL PREDICTOR" in out and "x the null predictor's" in out
    assert main([*argv, "--lr", "1e-6", "--out", str(tmp_path / "b"), "--strict"]) == 1
    from lagbench.reports.build import build_sections

    sections = build_sections(tmp_path / "a", tmp_path / "rep")
    assert any("Not clearly better than the null predictor" in getattr(b, "text", "") for s in sections for b in s.blocks)


def test_a_fit_that_learned_says_ok_with_its_ratio(data, tmp_path, capsys):
    assert main(["fit", "--data", str(data), "--model", "baseline", "--steps", "1500", "--hidden", "32,32",
                 "--lr", "3e-3", "--quiet", "--strict", "--out", str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ok: ") and "x the null predictor's" in out and "BETTER" not in out
    from lagbench.reports.build import build_sections

    sections = build_sections(tmp_path / "c", tmp_path / "rep")
    assert not any("Not clearly better" in getattr(b, "text", "") for s in sections for b in s.blocks)
