"""Adopt a `lagbench tune` ledger: its choices become the claim's protocol under its profile.

`python -m lagbench.replication.tuning.adopt LEDGER.json ...` writes each ledger's choices into
`replication/claims/tuned.json` (read by `replication.claims.tuned`), after checking that the ledger is the
whole declared search (`kind` "search": every configuration of the grid, a partial search or a width sweep
is a trial), scored on the development split, that every trained model of the claim was searched alike (the
same number of configurations), and that each choice was confirmed on at least `CONFIRM_SEEDS` development
seeds. The record names the ledger's file (committed under `docs/lab/search/`). Register the changed protocols next (`python -m lagbench.replication.claims.registration
--note ...`): a verdict rests on a registered protocol only.
"""
from __future__ import annotations

import argparse
import json
from datetime import date
from pathlib import Path

from lagbench.replication.claims import get, tuned
from lagbench.replication.training.protocol import canonical_hash
from lagbench.replication.tuning import search
from lagbench.replication.tuning.tune import CONFIRM_SEEDS

ROOT = Path(__file__).resolve().parents[2]


def _named(path: Path) -> str:
    """The ledger's path relative to the project's root where it lies inside it (committed), else as given."""
    try:
        return path.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return str(path)


def adopt(ledger_file, today: str | None = None) -> dict:
    """Write the choices of a `lagbench tune` ledger into tuned.json; the record written."""
    path = Path(ledger_file)
    try:
        ledger = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"cannot read {path}: {e}") from None
    try:
        claim, profile = get(ledger["claim"]), ledger["profile"]
    except (KeyError, TypeError) as e:
        raise ValueError(f"{path} is not a ledger of `lagbench tune` ({e})") from None
    if ledger.get("split") != "dev" or any(m.get("scored_on") != "dev" for m in ledger.get("models", {}).values()):
        raise ValueError(f"{path} was not scored on the development split; only a dev ledger may choose")
    if ledger.get("kind") != "search":
        raise ValueError(f"{path} is a {ledger.get('kind', 'trial')}, not the whole declared search; only a search "
                         "may choose (lagbench tune without --configs or --widths)")
    trained = [m.label for m in claim.models if tuned.searched(claim, m, profile)]
    missing = [x for x in trained if x not in ledger["models"]]
    if missing:
        raise ValueError(f"{path} has no search for {', '.join(missing)}: every model is tuned alike or none")
    tried = {ledger["models"][x]["configs_tried"] for x in trained}
    if len(tried) != 1:
        raise ValueError(f"{path} tried unequal numbers of configurations ({sorted(tried)}) across models")
    if min(tried) < search.SIZE:
        raise ValueError(f"{path} tried {min(tried)} configurations; the search has {search.SIZE}")
    short = [x for x in trained if ledger["models"][x]["chosen"] is not None
             and len(ledger["models"][x].get("confirm_seeds") or []) < CONFIRM_SEEDS]
    if short:
        raise ValueError(f"{path}: {', '.join(short)} not confirmed on {CONFIRM_SEEDS} development seeds")
    models = {}
    for x in trained:
        m = ledger["models"][x]
        knobs = m["chosen_knobs"] or {k: 1.0 for k in ledger["search"]}   # nothing scored: the registered setting
        # the chosen configuration's mean over the confirmation seeds (else its first stage's score)
        score = ({**m["scores"], **(m.get("confirmation") or {})}.get(str(m["chosen"]))
                 if m["chosen"] is not None else None)
        models[x] = {"knobs": knobs, "configs_tried": m["configs_tried"], "score": score,
                     "confirm_seeds": m.get("confirm_seeds") or []}
    rec = {"ledger": _named(path), "ledger_hash": canonical_hash(ledger, 16), "split": "dev", "seeds": ledger["seeds"],
           "frameworks": ledger["frameworks"], "configs": tried.pop(), "search": ledger["search"],
           "adopted": today or date.today().isoformat(), "models": models,
           **({"edge_limits": ledger["edge_limits"]} if ledger.get("edge_limits") else {})}
    data = json.loads(tuned.FILE.read_text()) if tuned.FILE.is_file() else {}
    data.setdefault(claim.id, {})[profile] = rec
    tuned.FILE.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    tuned.records.cache_clear()
    return rec


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m lagbench.replication.tuning.adopt",
                                description="Adopt the choices of a `lagbench tune` ledger as the claim's protocol "
                                            "under its profile (then register it: python -m "
                                            "lagbench.replication.claims.registration --note ...).")
    p.add_argument("ledgers", nargs="+", metavar="LEDGER", help="ledger.json files of `lagbench tune`")
    args = p.parse_args(argv)
    for f in args.ledgers:
        try:
            rec = adopt(f)
        except ValueError as e:
            p.exit(2, f"error: {e}\n")
        print(f"{f}: " + ", ".join(f"{k} lr x{v['knobs']['lr']:.3g} width x{v['knobs']['width']:g}"
                                   for k, v in rec["models"].items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
