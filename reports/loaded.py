"""What a loaded results folder is (``reports.load.load_results`` fills it): a :class:`Unit` per unit folder,
its ``result.json`` held and its other files read on demand (None where missing, unreadable or the unit is
corrupt), and :class:`Results`, everything read from the folder with the problems found. ``protocol_of``: a
result's training protocol."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.training.protocol import Protocol


def protocol_of(result: dict) -> Protocol | None:
    """A result's training protocol (any recorded version), or None where none is readable."""
    try:
        return Protocol.from_dict(result["protocol"])
    except (KeyError, TypeError, ValueError):
        return None


@dataclass(frozen=True)
class Unit:
    """One claim x framework x model x seed. ``rel`` is the unit folder relative to the results root."""

    claim: str
    framework: str
    model: str
    seed: str
    path: Path
    rel: str
    status: str
    reason: str | None = None
    result: dict = field(default_factory=dict, repr=False)

    @property
    def protocol(self) -> Protocol | None:
        return protocol_of(self.result)

    def metric(self, name: str) -> float | None:
        value = (self.result.get("metrics") or {}).get(name)
        return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else None

    def table(self, name: str) -> pd.DataFrame | None:
        """A CSV of this unit (``train_log.csv``, ``rollouts.csv``, ``timeseries.csv``), or None."""
        path = self.path / name
        if self.status == "corrupt" or not path.is_file():
            return None
        try:
            return pd.read_csv(path)
        except (ValueError, OSError):
            return None

    def arrays(self) -> dict[str, np.ndarray] | None:
        """The arrays of ``arrays.npz`` (no pickles), or None."""
        path = self.path / "arrays.npz"
        if self.status == "corrupt" or not path.is_file():
            return None
        try:
            with np.load(path, allow_pickle=False) as npz:
                return {k: np.asarray(npz[k]) for k in npz.files}
        except (ValueError, OSError):
            return None


@dataclass
class Results:
    root: Path
    run: dict | None = None
    claims: list[dict] = field(default_factory=list)
    units: list[Unit] = field(default_factory=list)
    verdicts: dict[str, dict] = field(default_factory=dict)          # recomputed from the unit files
    stored_verdicts: dict[str, dict] = field(default_factory=dict)   # summary/verdicts.json as written
    verdict_profile: str | None = None
    verdict_split: str | None = None
    split: str = "dev"   # the split judged (`replication.run.splits`): run.json's, else verdicts.json's
    planned_missing: list[str] = field(default_factory=list)
    unfinished: bool = False
    units_csv: pd.DataFrame | None = None
    listed_missing: list[str] = field(default_factory=list)
    bench: dict[str, pd.DataFrame] = field(default_factory=dict)
    train_target: dict[str, pd.DataFrame] = field(default_factory=dict)  # train_target/ (lagbench train-target)
    bench_gpu: dict[str, pd.DataFrame] = field(default_factory=dict)  # bench_gpu/ (lagbench bench --gpu)
    machine: dict | None = None
    machine_gpu: dict | None = None
    problems: list[str] = field(default_factory=list)

    def usable(self, claim: str | None = None) -> list[Unit]:
        return [u for u in self.units if u.status == "ok" and (claim is None or u.claim == claim)]

    def claim_units(self, claim: str) -> list[Unit]:
        return [u for u in self.units if u.claim == claim]

    @property
    def frameworks(self) -> list[str]:
        declared = list((self.run or {}).get("frameworks") or [])
        seen = sorted({u.framework for u in self.units} - set(declared))
        return [str(f) for f in declared] + seen
