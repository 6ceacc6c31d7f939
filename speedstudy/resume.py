"""Stage checkpoints of the speed study: `lagbench bench --resume` reuses the stages that an earlier,
interrupted run into the same folder finished.

Each finished stage writes OUT/bench/stages/<stage>.json: the preset, the commit, the notes the stage added
and its rows by output file (JSON that keeps NaN and infinities, so the rows come back as they were
computed). A resumed run takes a stage from there only when the preset and the commit match its own; a
checkpoint of another preset or commit, or one that does not parse, is reported on stderr and the stage
runs again. The commit is git's HEAD: uncommitted edits do not change it, so after editing the code run
without --resume. Without --resume every stage runs and overwrites its checkpoint.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from lagbench.files.results import atomic_write_bytes

__all__ = ["StageCache"]


def _plain(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")


class StageCache:
    """`load(stage)` -> (tables {file name: rows}, notes) or None; `save(stage, tables, notes)`."""

    def __init__(self, bench: Path, preset: str, commit: str | None, resume: bool, warn=None):
        self.folder, self.preset, self.commit, self.resume = Path(bench) / "stages", preset, commit, resume
        self.warn = warn or (lambda msg: print(f"lagbench bench: {msg}", file=sys.stderr))
        self.reused: list[str] = []

    def path(self, stage: str) -> Path:
        return self.folder / (stage.replace(" ", "_") + ".json")

    def load(self, stage: str):
        path = self.path(stage)
        if not self.resume or not path.is_file():
            return None
        try:
            d = json.loads(path.read_text())
            tables, notes = d["tables"], d["notes"]
            if not isinstance(tables, dict) or not all(isinstance(v, list) for v in tables.values()) \
                    or not isinstance(notes, list):
                raise ValueError("tables or notes of the wrong type")
        except (OSError, ValueError, KeyError, TypeError) as e:
            self.warn(f"stage {stage!r}: checkpoint {path} is unreadable ({type(e).__name__}: {e}); running it again")
            return None
        if (d.get("preset"), d.get("commit")) != (self.preset, self.commit):
            self.warn(f"stage {stage!r}: checkpoint {path} is from preset {d.get('preset')} at commit "
                      f"{d.get('commit')}, this run is {self.preset} at {self.commit}; running it again")
            return None
        self.reused.append(stage)
        return tables, notes

    def save(self, stage: str, tables: dict, notes: list) -> None:
        d = {"stage": stage, "preset": self.preset, "commit": self.commit, "notes": list(notes),
             "tables": {k: list(v) for k, v in tables.items()}}
        atomic_write_bytes(self.path(stage), json.dumps(d, default=_plain).encode())
