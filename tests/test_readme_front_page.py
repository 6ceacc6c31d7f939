"""The README is a front page: at most 200 lines, and every relative link in it names a file or folder of the
repository (the rest of the documentation lives under docs/, reached through those links)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 200
# [text](target "title") and reference definitions "[label]: target"
INLINE = re.compile(r"\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s*\[[^\]]+\]:\s*<?(\S+?)>?(?:\s|$)", re.M)
SCHEME = re.compile(r"^[a-z][a-z0-9+.-]*:", re.I)   # http:, https:, mailto:, ...


def relative_links(text: str) -> list[str]:
    """The link targets of a Markdown text that point inside the repository, without their #anchors."""
    targets = INLINE.findall(text) + REFERENCE.findall(text)
    return [t.split("#", 1)[0] for t in targets if not SCHEME.match(t) and not t.startswith("#")]


def broken_links(text: str, base: Path) -> list[str]:
    return [t for t in relative_links(text) if not (base / t).exists()]


def test_the_readme_has_at_most_200_lines():
    n = len((ROOT / "README.md").read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, f"README.md has {n} lines; a front page has at most {MAX_LINES}: move the rest to docs/"


def test_every_relative_link_in_the_readme_exists():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert relative_links(text), "no relative link found in README.md: the front page links the rest from docs/"
    assert broken_links(text, ROOT) == []


def test_the_link_check_finds_a_missing_file_and_skips_urls_and_anchors(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "here.md").write_text("x", encoding="utf-8")
    text = ("[a](docs/here.md) [b](docs/gone.md#part) [c](https://example.org/x.md) [d](#install)\n"
            "[e](docs/here.md \"title\") ![f](docs/missing.png)\n[g]: docs/nowhere.md\n")
    assert relative_links(text) == ["docs/here.md", "docs/gone.md", "docs/here.md", "docs/missing.png",
                                    "docs/nowhere.md"]
    assert broken_links(text, tmp_path) == ["docs/gone.md", "docs/missing.png", "docs/nowhere.md"]
