"""Frozen protocols: what decides each claim under each profile, registered before its test-split run.

`fingerprint(claim, profile, adopted=None) -> dict`: everything that decides the claim's numbers and its verdict
under the profile, read from what runs (`resolved.resolved`, the adopted tuning `adopted` applied; default
tuned.json's): the frameworks it is decided in (the profile's), per model that runs, its model spec fields,
widths and protocol; the evaluation config and the evaluation routines' version
(`replication.evaluation.version`); the seed count; the competence bars; the parts (the models they read
and control, their rule, the rule's parameters and a hash of the rule's code with every rule and
statistics function it reaches); the variants; the metric.
`protocol_hash(claim, profile, adopted=None) -> str`: its `canonical_hash` (16 hex digits of the sha256 of its
canonical JSON).
`registrations()`: the committed records (`registrations.json`): {claim id: [line, ...]} oldest first, a
line {"profile", "protocol_hash", "frozen" (the date it was frozen), "tuned_on" (the split its choices
read), "note" (how it was chosen)}.
`status(claim, profile, committed=None, adopted=None) -> dict`: against the registrations `committed` (default:
the file's) {"protocol_hash", "registered" (a line holds this hash), "frozen" (that
line's date, else None), "tuned_on", "note", "registrations" (lines of this profile: more than one means the
protocol was changed after an earlier registration, each change disclosed)}. A protocol that matches no
line is unregistered: the tests forbid it, so a changed protocol is a new, dated line, never a silent edit.
`python -m lagbench.replication.claims.registration --note "..."` appends a line for every claim and profile whose
current protocol matches none (nothing else changes).
"""
from __future__ import annotations

import argparse
import inspect
import json
import re
from datetime import date
from functools import lru_cache
from pathlib import Path

from lagbench.replication.claims import bars, stats
from lagbench.replication.claims.base import PROFILES
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.evaluation.version import EVALUATION_VERSION
from lagbench.replication.training.protocol import canonical_hash

FILE = Path(__file__).with_name("registrations.json")
_SIMPLE = (str, int, float, bool, tuple, type(None))
_RULE_MODULES = ("lagbench.replication.claims.rules", "lagbench.replication.claims.stats")
_PACKAGE = re.compile(r"\blagbench\.")


def _relative(text: str) -> str:
    """Module names in a rule's code as the package names them inside (`replication.claims.rules`), so that the
    hash follows what a rule compares and not the name it is installed under."""
    return _PACKAGE.sub("", text)


def _code(fn, seen: set) -> list:
    """The source of a function and of every function it closes over or calls by a module-level name in
    the rule and statistics modules (the comparison code of a rule), each once, in a stable order."""
    if id(fn) in seen or not callable(fn):
        return []
    seen.add(id(fn))
    code = getattr(fn, "__code__", None)
    if code is None:
        return [repr(fn)]
    try:
        text = inspect.getsource(fn)
    except (OSError, TypeError):
        text = code.co_code.hex()
    out = [_relative(f"{fn.__module__}.{fn.__qualname__}:\n{text}")]
    for c in getattr(fn, "__closure__", None) or ():
        v = c.cell_contents
        if inspect.isfunction(v):
            out += _code(v, seen)
    glob = getattr(fn, "__globals__", {})
    for name in code.co_names:
        g = glob.get(name)
        if inspect.isfunction(g) and g.__module__ in _RULE_MODULES:
            out += _code(g, seen)
        elif inspect.isclass(g) and g.__module__ in _RULE_MODULES:
            try:
                out.append(_relative(f"{g.__module__}.{g.__qualname__}:\n{inspect.getsource(g)}"))
            except (OSError, TypeError):
                pass
    return out


def _constants() -> dict:
    """The module constants the rules read (the interval's level)."""
    return {"stats.LEVEL": stats.LEVEL}


def _rule(rule) -> dict:
    """A part's rule: its name, the plain values it closes over (its models, metric and thresholds), and a
    hash of its code and of every rule or statistics function it reaches, so that any change to how a rule
    compares is a new protocol."""
    cells = [c.cell_contents for c in (getattr(rule, "__closure__", None) or ())]
    return {"rule": getattr(rule, "__qualname__", repr(rule)),
            "params": [repr(v) for v in cells if isinstance(v, _SIMPLE)],
            "code": canonical_hash({"sources": _code(rule, set()), "constants": _constants()}, 16)}


def fingerprint(claim, profile: str, adopted: dict | None = None) -> dict:
    run = resolved(claim, profile, adopted)
    models = {m.label: {"spec": m.spec, "hidden": list(m.hidden), "protocol": m.protocol.to_dict()} for m in run.models}
    return {"claim": claim.id, "profile": profile, "frameworks": list(run.frameworks), "models": models,
            "eval": run.eval, "evaluation_version": EVALUATION_VERSION,
            "seeds": run.seeds, "metric": claim.metric, "bars": [b.describe() for b in claim.bars],
            "bars_code": canonical_hash({"source": _relative(inspect.getsource(bars)), "share": bars.SHARE}, 16),
            "parts": [{**p.describe(), **_rule(p.rule)} for p in claim.parts],
            "variants": [v.describe() for v in claim.variants]}


def protocol_hash(claim, profile: str, adopted: dict | None = None) -> str:
    return canonical_hash(fingerprint(claim, profile, adopted), 16)


@lru_cache(maxsize=1)
def registrations() -> dict:
    return json.loads(FILE.read_text()) if FILE.is_file() else {}


def status(claim, profile: str, committed: dict | None = None, adopted: dict | None = None) -> dict:
    h = protocol_hash(claim, profile, adopted)
    lines = [x for x in (registrations() if committed is None else committed).get(claim.id, [])
             if x["profile"] == profile]
    hit = next((x for x in reversed(lines) if x["protocol_hash"] == h), None)
    return {"protocol_hash": h, "registered": hit is not None, "frozen": hit and hit["frozen"],
            "tuned_on": hit and hit["tuned_on"], "note": hit and hit["note"], "registrations": len(lines)}


def register(note: str, tuned_on: str = "dev", today: str | None = None) -> list[str]:
    """Append a line for each claim and profile whose current protocol matches none; the names added."""
    from lagbench.replication.claims import CLAIMS

    data = json.loads(FILE.read_text()) if FILE.is_file() else {}
    added = []
    for c in CLAIMS.values():
        for profile in PROFILES:
            if not status(c, profile)["registered"]:
                data.setdefault(c.id, []).append({"profile": profile, "protocol_hash": protocol_hash(c, profile),
                                                  "frozen": today or date.today().isoformat(),
                                                  "tuned_on": tuned_on, "note": note})
                added.append(f"{c.id}/{profile}")
    if added:
        FILE.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
        registrations.cache_clear()
    return added


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m lagbench.replication.claims.registration",
                                description="Register (freeze) every claim protocol that matches no registration.")
    p.add_argument("--note", required=True, help="how the protocols were chosen")
    p.add_argument("--tuned-on", default="dev", choices=("dev",), help="the split the choices read")
    args = p.parse_args(argv)
    added = register(args.note, args.tuned_on)
    print(f"registered {len(added)}: {', '.join(added)}" if added else "every protocol is registered")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
