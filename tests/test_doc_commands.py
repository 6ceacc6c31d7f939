"""Every command in a shell block of the README and of docs/*.md is one the suite accepts as written: each
`lagbench` line parses with the command line's own parser and prints no notice of an old spelling, each
`tox -e NAME` names an environment of tox.ini, each `pip install -e ".[EXTRA]"` an extra of pyproject.toml.
The commands cheap enough to run (`lagbench list`, `--version`, `--help`) run here; the README's
examples run end to end in their own tests (tests/replication/run/test_your_model_example.py,
tests/replication/fit/test_readme_data_example.py, tests/replication/fit/test_fit_example.py)."""
import configparser
import re
import shlex
import tomllib
from pathlib import Path

import pytest

from lagbench.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SHELL = ("bash", "sh", "shell", "console")
CHEAP = ("--help", "--version")   # a dry run probes trainings (on the device it names): not cheap


def fenced_blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of each fenced block of a Markdown text, in order; a fence closes only on a line of
    its own backticks, so a block's language never leaks into the next."""
    blocks, lang, body = [], None, []
    for line in text.splitlines():
        fence = re.match(r"^\s*```\s*([\w+-]*)\s*$", line)
        if lang is None and fence:
            lang, body = fence.group(1) or "", []
        elif lang is not None and re.match(r"^\s*```\s*$", line):
            blocks.append((lang, "\n".join(body)))
            lang = None
        elif lang is not None:
            body.append(line)
    return blocks


def shell_lines(text: str) -> list[str]:
    """The commands of the shell blocks: continuations joined, comments and prompts stripped."""
    out = []
    for lang, body in fenced_blocks(text):
        if lang not in SHELL:
            continue
        for line in body.replace("\\\n", " ").splitlines():
            line = re.sub(r"(^|\s)#.*$", "", line).strip()
            line = line[2:] if line.startswith("$ ") else line
            if line:
                out.append(line)
    return out


def commands(tool: str) -> list[tuple[str, list[str]]]:
    found = []
    for doc in DOCS:
        for line in shell_lines(doc.read_text(encoding="utf-8")):
            for part in re.split(r"\s*(?:&&|;|\|\|)\s*", line):
                words = shlex.split(part)
                if words and words[0] == tool:
                    found.append((f"{doc.relative_to(ROOT)}: {part}", words[1:]))
    return found


LAGBENCH = commands("lagbench")


def test_the_docs_hold_commands_to_check():
    assert len(LAGBENCH) >= 20, "the fence parser lost the docs' command blocks"
    assert any(where.startswith("README.md") for where, _ in LAGBENCH)


@pytest.mark.parametrize("where,argv", LAGBENCH, ids=[w for w, _ in LAGBENCH])
def test_every_lagbench_command_in_the_docs_parses_as_written(where, argv, capsys):
    try:
        build_parser().parse_args(argv)
    except SystemExit as e:
        if not (e.code == 0 and any(a in ("--help", "-h", "--version") for a in argv)):
            pytest.fail(f"{where}\n{capsys.readouterr().err}")
    err = capsys.readouterr().err
    assert "note:" not in err, f"{where} uses an old spelling: {err}"


@pytest.mark.parametrize("where,argv", [(w, a) for w, a in LAGBENCH if not a or a[0] == "list"
                                        or any(c in a for c in CHEAP)],
                         ids=lambda x: x if isinstance(x, str) else "")
def test_the_cheap_commands_of_the_docs_run(where, argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    try:
        code = main(argv)
    except SystemExit as e:
        code = e.code
    assert code == 0, f"{where}\n{capsys.readouterr().err}"


def test_every_tox_environment_the_docs_name_exists():
    ini = configparser.ConfigParser(interpolation=None)
    ini.read(ROOT / "tox.ini")
    envs = {s.split(":", 1)[1] for s in ini.sections() if s.startswith("testenv:")}
    named = [(w, a[a.index("-e") + 1]) for w, a in commands("tox") if "-e" in a]
    assert named, "no `tox -e` in the docs"
    assert [(w, e) for w, e in named if not set(e.split(",")) <= envs] == []


def test_every_extra_the_docs_install_exists():
    extras = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"])
    asked = [(w, x) for w, a in commands("pip") for word in a
             for x in re.findall(r"\[([\w,-]+)\]", word) if word.startswith((".", "lagbench"))]
    assert asked, "no `pip install ...[extra]` in the docs"
    assert [(w, x) for w, x in asked if not set(x.split(",")) <= extras] == []


def test_the_checks_catch_an_unknown_option_and_a_lost_fence(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["run", "--no-such-option"])
    text = "```bash\nlagbench list\n```\n```python\nx = 1\n```\n```\nlagbench nothing\n```\n"
    assert fenced_blocks(text) == [("bash", "lagbench list"), ("python", "x = 1"), ("", "lagbench nothing")]
    assert shell_lines(text) == ["lagbench list"]
