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
  sittings of the run) and verify/ (`lagbench verify`); predict/ (`lagbench evaluate --predict`: records
  whose result.json lists their files).
- the studies beside the claims that the report reads, each a folder of OUT (`STUDIES`: `lagbench control`,
  `online --system four_joint_arm`, `robustness`, `stiff`, `bench`, `train-target`), only the files of it the
  report reads (`reports/sections_*.py`, `reports/load.py`): a study's recordings (data/), fitted models
  (fits/), the bench's stage checkpoints and trained weights stay out.
- `.gitignore` (`gitignore()`, written by `prepare`, from `RULES`), so that git ignores everything else:
  the training cache `trained/`, the folder locks and temporary files (hidden names), the estimate's probes
  (this machine's timings), results set aside as superseded, a checkpoint that is not kept.

A unit counts as finished in a store (`runner.is_current(..., registration=True)`) when it is current in any
run (its split, protocol, model spec, evaluation config and version unchanged) and the registration hash it
records ("protocol_hash": `claims.registration.protocol_hash` of its claim and profile when it was made) is
the claim's now. The commit may differ; the registration may not: a unit made under another registration
(another protocol, rule or bar of its claim) is set aside and redone, never mixed in.

`kept_files(out)`: the files git keeps (`RULES` read as git reads them); `size(out)` their bytes;
`size_line(out)` says it against `BUDGET_MB`, the budget a store is held to (a warning past it).
"""
from __future__ import annotations

import logging
import os
from fnmatch import fnmatchcase
from pathlib import Path

from lagbench.files import results as R

log = logging.getLogger("lagbench")
BUDGET_MB = 150                      # what a committed store may weigh (`size_line` warns past it)
CHECKPOINTS = ("delan_arm",)         # claims whose checkpoints a later step loads (claim 12's control study)
REMOVED = ("checkpoint.npz",)        # what a finished unit of any other claim does without
# kept whole, beside units/: the run's records, `lagbench verify`'s and `lagbench evaluate --predict`'s
RECORDS = ("run.json", "claims.json", "summary", "runs", "verify", "predict")
STUDIES = {   # a study's folder: the files of it the report reads (what else the study writes stays out)
    "control": ("tracking.csv", "traces.npz"),                                # lagbench control
    "control_four_joint_arm": ("study.json", "tracking.csv", "traces.npz"),   # lagbench control --system ...
    "online_four_joint_arm": ("setup.json", "summary.csv"),                   # lagbench online --system ...
    "robustness": ("study.json", "scenes.csv", "recommendation.csv"),         # lagbench robustness
    "stiff": ("solvers.csv", "choice.json"),                                  # lagbench stiff
    "bench": ("*.csv", "machine.json", "targets.json"),                       # lagbench bench
    "bench_gpu": ("*.csv", "machine.json", "targets.json"),                   # lagbench bench --gpu
    "train_target": ("*.csv",),                                               # lagbench train-target
}


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


def _rules() -> tuple[str, ...]:
    """The `.gitignore`'s patterns, in order (the last that matches a path decides; a folder ignored hides
    all it holds): everything ignored, then the records, the units (less the checkpoints not kept) and the
    studies' files taken back, then superseded results and hidden names (locks, temporary files) left out
    wherever they are."""
    records = tuple(f"!/{name}{'/' if '.' not in name else ''}" for name in RECORDS)
    units = ("!/units/", *(f"/units/**/{name}" for name in REMOVED),
             *(f"!/units/{claim}/**/{name}" for claim in CHECKPOINTS for name in REMOVED))
    studies = tuple(line for folder, files in STUDIES.items()
                    for line in (f"!/{folder}/", f"/{folder}/*", *(f"!/{folder}/{name}" for name in files)))
    return ("/*", *records, *units, *studies, "**/superseded-*/", "**/.*", "!/.gitignore")


RULES = _rules()


def gitignore() -> str:
    return ("# a lagbench store (docs/store.md): git keeps what a resumed run, the verdicts and the report read\n"
            + "".join(f"{rule}\n" for rule in RULES))


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


def _match(pattern: list, parts: tuple) -> bool:
    """Whether a path (its names) matches a pattern anchored at OUT (its names) as git matches it: `*` within
    a name, `**` any number of names."""
    if not pattern:
        return not parts
    if pattern[0] == "**":
        return any(_match(pattern[1:], parts[k:]) for k in range(len(parts) + 1))
    return bool(parts) and fnmatchcase(parts[0], pattern[0]) and _match(pattern[1:], parts[1:])


def _ignored(parts: tuple, folder: bool) -> bool:
    """Whether `RULES` ignore the path of OUT with these names (a folder's or a file's), its folders aside."""
    verdict = False
    for rule in RULES:
        pattern = rule.removeprefix("!")
        if (folder or not pattern.endswith("/")) and _match(pattern.strip("/").split("/"), parts):
            verdict = not rule.startswith("!")
    return verdict


def kept_files(out) -> list[Path]:
    """The files of OUT that its `.gitignore` keeps, relative to OUT, sorted (an ignored folder is not
    entered: git takes nothing under it)."""
    out, kept = Path(out), []
    for root, folders, files in os.walk(out):
        rel = Path(root).relative_to(out).parts
        folders[:] = [f for f in folders if not _ignored((*rel, f), folder=True)]
        kept += [Path(*rel, f) for f in files if not _ignored((*rel, f), folder=False)]
    return sorted(kept)


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
