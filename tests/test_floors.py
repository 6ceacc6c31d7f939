"""The house's floors: a package imports only its own floor and the floors below it, at module level or inside
a function. The ground floor (`lagbench.files`: result files, the lock, a user's code and data) imports nothing
of the suite; the command line (`lagbench.cli`) sits above every package."""
import ast

from test_import_cycles import _modules

FLOORS = [("lagbench.files", "lagbench.validate", "lagbench.options"), ("lagbench.systems",), ("lagbench.models",), ("lagbench.replication",),
          ("lagbench.speedstudy", "lagbench.reports"), ("lagbench.cli", "lagbench.cli_commands", "lagbench.cli_exits",
          "lagbench.cli_parser", "lagbench.results_cli", "lagbench.__main__")]


def _floor(module: str) -> int | None:
    for i, names in enumerate(FLOORS):
        if any(module == n or module.startswith(n + ".") for n in names):
            return i
    return None


def _imports(path, mods) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out |= {f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in mods else node.module for a in node.names}
    return {t for t in out if t.startswith("lagbench.")}


def upward(mods) -> list[str]:
    bad = []
    for m, path in sorted(mods.items()):
        own = _floor(m)
        for t in sorted(_imports(path, mods)):
            theirs = _floor(t)
            if own is not None and theirs is not None and theirs > own:
                bad.append(f"{m} imports {t}")
    return bad


def test_no_package_imports_a_floor_above_it():
    mods = _modules()
    assert all(_floor(m) is not None for m in mods if m != "lagbench"), "a module on no floor"
    assert upward(mods) == []


def test_the_check_sees_an_upward_import(tmp_path):
    low = tmp_path / "low.py"
    low.write_text("def f():\n    from lagbench.replication.run import runner\n")
    assert upward({"lagbench.systems.low": low, "lagbench.replication.run.runner": low}) == [
        "lagbench.systems.low imports lagbench.replication.run.runner"]
