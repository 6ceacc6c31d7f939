"""`lagbench report --out` is a folder the tool owns: it writes no file through a symlink and removes
only files an earlier build wrote and nobody has changed since (issue 25, case 4); `--results` must
name a results folder (case 5)."""

import sys

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


def test_only_the_tools_own_unchanged_files_are_removed(small_results_dir, tmp_path):
    out = tmp_path / "out"
    first = build_report(small_results_dir, out, pdf=False)["figures"]
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


def test_a_killed_builds_temporaries_and_figures_are_cleaned_by_the_next(results_dir, tmp_path):
    """A build killed part-way (issue 58, item 7): its half-written temporaries go at the next build, and
    the figures it wrote are on record, so the next build removes those it does not write again."""
    from replication.results import writing
    from reports import output

    out = tmp_path / "out"
    with writing():   # the killed build's process: its lock goes with it
        output.prepare(out)
        stray = output.write(out / "figures" / "gone_claim_energy.png", b"from the killed build")
    (out / ".REPORT.md.ab12cd34.tmp").write_bytes(b"half")
    (out / "figures" / ".x_energy.png.zz99yy88.tmp").write_bytes(b"half")
    (out / "figures" / ".notes.tmp").write_text("a user's own file")      # not our pattern: kept
    build_report(tmp_path / "empty", out, pdf=False)                      # the next build, no figures
    assert not stray.exists()
    assert not (out / ".REPORT.md.ab12cd34.tmp").exists() and not (out / "figures" / ".x_energy.png.zz99yy88.tmp").exists()
    assert (out / "figures" / ".notes.tmp").read_text() == "a user's own file"


def test_report_prints_a_path_with_undecodable_bytes_escaped(small_results_dir, tmp_path):
    import os
    import subprocess
    import sys

    out = os.fsencode(str(tmp_path)) + b"/rep\xffort"
    env = {**os.environ, "PYTHONIOENCODING": "utf-8"}
    r = subprocess.run([sys.executable, "-m", "replication.cli", "report", "--results", str(small_results_dir),
                        "--out", os.fsdecode(out)], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "\\udcff" in r.stdout and os.path.isdir(out)


def test_the_pdf_shows_characters_its_fonts_lack_as_code_points():
    """CJK in a user's path (issue 58, item 7): U+XXXX in the PDF's source instead of empty boxes; the
    report's own symbols stay as they are."""
    from reports.pdf import lit

    s = lit('data/中文-한국-ファイル.csv: "q̇" γ × 3 − 1 ≈ 2 😀')
    assert "U+4E2D" in s and "U+D55C" in s and "U+30D5" in s and "U+1F600" in s
    assert not any(c in s for c in "中한フ😀")
    assert "q̇" in s and "γ × 3 − 1 ≈ 2" in s and '\\"' in s


def test_the_default_report_folder_follows_the_results_folder(small_results_dir, tmp_path, monkeypatch):
    """`report --results X/full` writes report/full, never over another run's report/quick."""
    import shutil

    full = tmp_path / "runs" / "full"
    shutil.copytree(small_results_dir, full)
    monkeypatch.chdir(tmp_path)
    assert main(["report", "--results", str(full)]) in (0, None)
    assert (tmp_path / "report" / "full" / "REPORT.md").is_file() and not (tmp_path / "report" / "quick").exists()


def test_no_pdf_writes_the_markdown_alone_and_a_missing_typst_says_what_to_do(small_results_dir, tmp_path,
                                                                               monkeypatch, capsys):
    out = tmp_path / "md"
    assert main(["report", "--results", str(small_results_dir), "--out", str(out), "--no-pdf"]) in (0, None)
    assert (out / "REPORT.md").is_file() and not (out / "REPORT.pdf").exists() and not (out / "REPORT.typ").exists()
    monkeypatch.setitem(sys.modules, "typst", None)   # `import typst` raises ImportError
    capsys.readouterr()
    assert main(["report", "--results", str(small_results_dir), "--out", str(tmp_path / "nopdf")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lagbench: error: the PDF report needs typst") and "--no-pdf" in err and "\n" not in err
    assert (tmp_path / "nopdf" / "REPORT.md").is_file()   # written before the PDF: nothing computed is lost
