"""`lagbench report --out` is a folder the tool owns: it writes no file through a symlink and removes
only files an earlier build wrote and nobody has changed since (issue 25, case 4); `--results` must
name a results folder (case 5)."""

import pytest

from replication.cli import main
from reports import build_report


def test_a_symlinked_report_is_replaced_not_written_through(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    (out / "REPORT.md").symlink_to(victim)
    paths = build_report(tmp_path / "empty", out, pdf=False)
    assert victim.read_text() == "keep me"
    assert not paths["markdown"].is_symlink() and "Nothing was run" in paths["markdown"].read_text()


def test_only_the_tools_own_unchanged_files_are_removed(results_dir, tmp_path):
    out = tmp_path / "out"
    first = build_report(results_dir, out, pdf=False)["figures"]
    assert len(first) >= 2
    mine = out / "figures" / "my_plot.png"
    mine.write_bytes(b"user's own")
    edited = first[0]
    edited.write_bytes(b"edited by the user")
    build_report(tmp_path / "empty", out, pdf=False)  # makes no figures: the old ones are leftovers
    assert mine.read_bytes() == b"user's own" and edited.read_bytes() == b"edited by the user"
    assert not any(p.exists() for p in first[1:])


def test_a_symlinked_figures_folder_is_refused(tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "figures").symlink_to(elsewhere)
    with pytest.raises(ValueError, match="figures/ is a symlink"):
        build_report(tmp_path / "empty", out, pdf=False)
    assert list(elsewhere.iterdir()) == []


@pytest.mark.parametrize("make, words", [(False, "no such folder"), (True, "holds no lagbench results")])
def test_report_refuses_a_results_folder_that_is_not_one(tmp_path, capsys, make, words):
    results = tmp_path / "reslts"
    if make:
        results.mkdir()
    assert main(["report", "--results", str(results), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "--results" in err and words in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
