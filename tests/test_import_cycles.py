"""No import cycle among the suite's modules (module-level imports; a submodule importing its own package
is not a cycle). A function-level import is how a module reaches one that imports it back."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("lagbench", "systems", "models", "replication", "reports", "speedstudy")   # all under `lagbench`


def _modules() -> dict[str, Path]:
    mods = {}
    for folder in FOLDERS:
        for p in (ROOT / folder).rglob("*.py"):
            parts = p.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts if folder == "lagbench" else ("lagbench", *parts))
            mods[name.removesuffix(".__init__")] = p
    return mods


def _graph(mods) -> dict[str, set[str]]:
    graph = {m: set() for m in mods}
    for m, p in mods.items():
        for node in ast.parse(p.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            else:
                continue
            for t in names:
                while t and t not in mods:
                    t = t.rpartition(".")[0]
                if t and t != m and not m.startswith(t + "."):
                    graph[m].add(t)
    return graph


def _cycle(graph) -> list[str] | None:
    """One cycle as a path of modules, or None."""
    state: dict[str, int] = {}   # 1: on the current path, 2: done

    def visit(v, path):
        state[v] = 1
        for w in sorted(graph[v]):
            if state.get(w) == 1:
                return [*path[path.index(w):], w]
            if w not in state:
                found = visit(w, [*path, w])
                if found:
                    return found
        state[v] = 2
        return None

    for v in sorted(graph):
        if v not in state:
            found = visit(v, [v])
            if found:
                return found
    return None


def test_no_import_cycle():
    cycle = _cycle(_graph(_modules()))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_check_finds_a_cycle():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None
