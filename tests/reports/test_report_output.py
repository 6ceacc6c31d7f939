"""`lagbench report --out` is a folder the tool owns: it writes no file through a symlink and removes
only files an earlier build wrote and nobody has changed since (issue 25, case 4); `--results` must
name a results folder (case 5)."""

import sys

import pytest

from lagbench.cli import main
from lagbench.reports import build_report


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


def test_a_killed_builds_temporaries_and_staging_folder_are_cleaned_by_the_next(tmp_path):
    """A build killed part-way (issue 58, item 7; issue 85, item 5): its half-written temporaries go at the next
    build, and so does its staging folder with what it wrote there; nothing of it reached the report."""
    from lagbench.files.results import writing
    from lagbench.reports import output

    out = tmp_path / "out"
    with writing():   # the killed build's process: its lock goes with it
        stage = output.prepare(out)
        stray = output.write(stage / "figures" / "gone_claim_energy.png", b"from the killed build")
    assert stage.parent == out and not (out / "figures" / stray.name).exists()
    (out / ".REPORT.md.ab12cd34.tmp").write_bytes(b"half")
    (out / "figures" / ".x_energy.png.zz99yy88.tmp").write_bytes(b"half")
    (out / "figures" / ".notes.tmp").write_text("a user's own file")      # not our pattern: kept
    build_report(tmp_path / "empty", out, pdf=False)                      # the next build, no figures
    assert not stage.exists() and not list(out.glob(output.STAGE + "*"))
    assert not (out / ".REPORT.md.ab12cd34.tmp").exists() and not (out / "figures" / ".x_energy.png.zz99yy88.tmp").exists()
    assert (out / "figures" / ".notes.tmp").read_text() == "a user's own file"


def test_report_prints_a_path_with_undecodable_bytes_escaped(small_results_dir, tmp_path):
    import os
    import subprocess
    import sys

    out = os.fsencode(str(tmp_path)) + b"/rep\xffort"
    env = {**os.environ, "PYTHONIOENCODING": "utf-8"}
    r = subprocess.run([sys.executable, "-m", "lagbench", "report", "--results", str(small_results_dir),
                        "--out", os.fsdecode(out)], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "\\udcff" in r.stdout and os.path.isdir(out)


def test_the_pdf_shows_characters_its_fonts_lack_as_code_points():
    """CJK in a user's path (issue 58, item 7): U+XXXX in the PDF's source instead of empty boxes; the
    report's own symbols stay as they are."""
    from lagbench.reports.pdf import lit

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


def _fake_pdf(label: bytes):
    """A stand-in for `write_pdf` (typst's compile is not what these tests are about): REPORT.typ and REPORT.pdf
    marked with `label`, written where the build asks."""
    from lagbench.reports import output

    def write_pdf(title, sections, out_dir):
        return output.write(out_dir / "REPORT.typ", label), output.write(out_dir / "REPORT.pdf", b"%PDF " + label)
    return write_pdf


def _files(out) -> dict:
    """Every file of a report folder and its bytes (the folder locks, which name the time, aside)."""
    return {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != ".lagbench.lock"}


def _other_results(small_results_dir, tmp_path):
    """The small results less one claim's units: a report that reads differently."""
    import shutil

    other = tmp_path / "other"
    shutil.copytree(small_results_dir, other)
    shutil.rmtree(other / "units" / "dp_energy")
    return other


def test_an_interrupted_rebuild_leaves_the_previous_report_whole(small_results_dir, tmp_path, monkeypatch, capsys):
    """Issue 85, item 5: never a new REPORT.md beside the previous build's REPORT.pdf."""
    import lagbench.reports.build
    from lagbench.reports import output

    out = tmp_path / "out"
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", _fake_pdf(b"first"))
    assert main(["report", "--results", str(small_results_dir), "--out", str(out)]) in (0, None)
    before = _files(out)

    def interrupted(title, sections, out_dir):
        raise KeyboardInterrupt
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", interrupted)
    capsys.readouterr()
    assert main(["report", "--results", str(_other_results(small_results_dir, tmp_path)), "--out", str(out)]) == 130
    assert "the previous report is left whole" in capsys.readouterr().err
    assert _files(out) == before and not list(out.glob(output.STAGE + "*"))


def test_without_typst_the_previous_pdf_goes_and_the_error_says_so(small_results_dir, tmp_path, monkeypatch, capsys):
    import lagbench.reports.build

    out = tmp_path / "out"
    real = lagbench.reports.build.write_pdf
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", _fake_pdf(b"first"))
    first = build_report(small_results_dir, out)["markdown"].read_text()
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", real)
    monkeypatch.setitem(sys.modules, "typst", None)   # `import typst` raises ImportError
    capsys.readouterr()
    assert main(["report", "--results", str(_other_results(small_results_dir, tmp_path)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the previous build's REPORT.pdf and REPORT.typ removed" in err, err
    assert (out / "REPORT.md").read_text() != first   # the new Markdown, alone
    assert not (out / "REPORT.pdf").exists() and not (out / "REPORT.typ").exists()


def test_a_signal_while_the_report_moves_in_arrives_after_it_is_whole(small_results_dir, tmp_path, monkeypatch):
    import os
    import signal
    import threading

    import lagbench.reports.build
    import lagbench.reports.output
    from lagbench.reports import output

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signal handlers are set in the main thread only")
    out = tmp_path / "out"
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", _fake_pdf(b"first"))
    first = build_report(small_results_dir, out)["markdown"].read_text()
    monkeypatch.setattr(lagbench.reports.build, "write_pdf", _fake_pdf(b"second"))
    replace, sent = os.replace, []

    def replace_then_stop(src, dst):   # SIGTERM right after the first output is moved into the report's folder
        replace(src, dst)
        if not sent and output.STAGE in str(src) and output.STAGE not in str(dst):
            sent.append(dst)
            os.kill(os.getpid(), signal.SIGTERM)

    class Stopped(Exception):
        pass

    def stop(signum, frame):
        raise Stopped

    monkeypatch.setattr(lagbench.reports.output.os, "replace", replace_then_stop)
    old = signal.signal(signal.SIGTERM, stop)
    try:
        with pytest.raises(Stopped):
            build_report(_other_results(small_results_dir, tmp_path), out)
    finally:
        signal.signal(signal.SIGTERM, old)
    assert sent and (out / "REPORT.pdf").read_bytes() == b"%PDF second" and (out / "REPORT.typ").read_bytes() == b"second"
    assert (out / "REPORT.md").read_text() != first and not list(out.glob(output.STAGE + "*"))
