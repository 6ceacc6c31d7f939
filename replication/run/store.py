"""A results folder kept as a store: a run carried in the repository (`lagbench run --store`).

A store holds only what a resumed run, the verdicts and the report read, so that `git add OUT` commits a run
that can stop at any point and go on from a fresh clone of a later commit, on another machine:

- each finished unit (`units/<claim>/<framework>/<model>/seed<k>/`): result.json and the tables and arrays
  its evaluation wrote (train_log.csv, rollouts.csv, timeseries.csv, arrays.npz: the report's figures and
  tables read them). Its checkpoint.npz is kept only for the claims in `CHECKPOINTS`, whose trained models a
  later step loads: claim 9's (`delan_arm`), which the closed-loop control study of claim 12 (`lagbench
  control`) drives the arm with. Any other unit's checkpoint is removed once the unit is finished
  (`keep_unit`): its result.json is written again listing the files it keeps, the removed ones named with
  their sha256 under "store": {"removed": {...}}, and checksummed again, so that it verifies
  (`results.load_result`, the report's `integrity.verify_unit`) without them.
- the run's records: run.json, claims.json, summary/, runs/ (each earlier invocation's run.json: the
  sittings of the run) and verify/ (`lagbench verify`).
- `.gitignore` (`gitignore()`, written by `prepare`), so that git ignores everything else: the training cache
  `trained/`, the folder lock, the estimate's probes (this machine's timings), results set aside as
  superseded, a checkpoint that is not kept.

A unit counts as finished in a store (`runner.is_current(..., registration=True)`) when it is current in any
run (its split, protocol, model spec, evaluation config and version unchanged) and the registration hash it
records ("protocol_hash": `claims.registration.protocol_hash` of its claim and profile when it was made) is
the claim's now. The commit may differ; the registration may not: a unit made under another registration
(another protocol, rule or bar of its claim) is set aside and redone, never mixed in.

`kept_files(out)`: the files git keeps (the `.gitignore`'s rules, written out); `size(out)` their bytes;
`size_line(out)` says it against `BUDGET_MB`, the budget a store is held to (a warning past it).
"""
from __future__ import annotations

import logging
from pathlib import Path

from lagbench.files import results as R

log = logging.getLogger("lagbench")
BUDGET_MB = 150                      # what a committed store may weigh (`size_line` warns past it)
CHECKPOINTS = ("delan_arm",)         # claims whose checkpoints a later step loads (claim 12's control study)
REMOVED = ("checkpoint.npz",)        # what a finished unit of any other claim does without
RECORDS = ("run.json", "claims.json", "summary", "runs", "verify")   # the run's records, beside units/


def registration_hash(source, profile: str) -> str | None:
    """The registration hash of a claim under a profile (`claims.registration.protocol_hash`); None for a
    unit of another source (a user's fit), which has no registration."""
    from lagbench.replication.claims.base import Claim
    from lagbench.replication.claims.registration import protocol_hash

    return protocol_hash(source, profile) if isinstance(source, Claim) else None


def same_registration(d: dict, unit, memo: dict) -> bool:
    """Whether the result `d` of `unit` records its claim's registration hash of now (`memo`: hashes already
    computed in this run, by claim and profile)."""
    key = (unit.claim.id, unit.profile)
    if key not in memo:
        memo[key] = registration_hash(unit.claim, unit.profile)
    return d.get("protocol_hash") == memo[key]


def gitignore() -> str:
    keep = "".join(f"!/{name}{'/' if '.' not in name else ''}\n" for name in RECORDS)
    removed = "".join(f"/units/**/{name}\n" for name in REMOVED)
    back = "".join(f"!/units/{claim}/**/{name}\n" for claim in CHECKPOINTS for name in REMOVED)
    return ("# a lagbench store (docs/store.md): git keeps what a resumed run, the verdicts and the report read\n"
            f"/*\n!/.gitignore\n{keep}!/units/\nsuperseded-*/\n/units/**/.*\n{removed}{back}")


def prepare(out) -> int:
    """Write OUT/.gitignore and remove what the store does without from every finished unit already there (a
    run stopped before it could); the number of units trimmed."""
    path = Path(out) / ".gitignore"
    if not path.is_file() or path.read_text() != gitignore():
        R.atomic_write_bytes(path, gitignore().encode())
    return prune(out)


def keep_unit(folder) -> bool:
    """Remove from a finished unit's folder what a store does without (its result.json first written again
    without them); False where nothing is removed: a kept claim's unit, one already trimmed, one whose result
    does not verify (unfinished or damaged: the run redoes it; nothing of it is touched)."""
    folder = Path(folder)
    try:
        d = R.load_result(folder)
    except R.CorruptResult:
        return False
    files = d.get("files") or {}
    gone = {n: h for n, h in files.items() if n in REMOVED}
    if d.get("claim") in CHECKPOINTS or not gone:
        return False
    store = dict(d.get("store") or {})
    store["removed"] = {**(store.get("removed") or {}), **gone}
    R.write_json(folder / "result.json", {**{k: v for k, v in d.items() if k != "checksum"}, "store": store,
                                         "files": {n: h for n, h in files.items() if n not in gone}}, checksum=True)
    for name in gone:   # after result.json: a stop in between leaves a unit that verifies all the same
        (folder / name).unlink(missing_ok=True)
    return True


def prune(out) -> int:
    return sum(keep_unit(f.parent) for f in sorted(Path(out).glob("units/*/*/*/seed*/result.json")))


def _kept(rel: Path) -> bool:
    parts = rel.parts
    if parts[0] == ".gitignore":
        return len(parts) == 1
    if parts[0] in RECORDS:
        return len(parts) > 1 or "." in parts[0]
    if parts[0] != "units" or any(p.startswith("superseded-") or p.startswith(".") for p in parts[1:]):
        return False
    return rel.name not in REMOVED or (len(parts) > 1 and parts[1] in CHECKPOINTS)


def kept_files(out) -> list[Path]:
    """The files of OUT that its `.gitignore` keeps, relative to OUT, sorted."""
    out = Path(out)
    return sorted(p.relative_to(out) for p in out.rglob("*") if p.is_file() and _kept(p.relative_to(out)))


def size(out) -> int:
    return sum((Path(out) / p).stat().st_size for p in kept_files(out))


def size_line(out) -> str:
    """What the store weighs against its budget, one line; a warning is logged past the budget."""
    mb = size(out) / 1e6
    line = (f"lagbench: store {out}: {len(kept_files(out))} files, {mb:.1f} MB of its {BUDGET_MB} MB budget "
            f"(what `git add {out}` commits; docs/store.md)")
    if mb > BUDGET_MB:
        log.warning("lagbench: store %s: %.1f MB, past its %d MB budget", out, mb, BUDGET_MB)
    return line
