"""Snapshots of a training in progress, so that a run killed mid-training continues where it was.

Why: a `full`-profile training of the double pendulum takes about half an hour on this CPU and `paper`
ones hours; without snapshots an interruption (Ctrl-C, a killed worker, the end of a session) throws away
every training in flight. With them the run resumes each from its last snapshot, and the resumed training
is the uninterrupted one bit for bit: the batch streams are indexed by step, and a snapshot holds the whole
state the next step reads (`tests/replication/training/test_snapshots.py` checks this in float64 and
float32, both frameworks, one model, a cohort, and the two phases of a scouted run).

A snapshot is taken by the one loop (`loop.train_members`, argument `snapshot`) after a step when
`due()` says so (every `every_s` seconds of wall time, `SNAPSHOT_EVERY_S` by default) and once when the
loop ends. It holds:
  arrays  the stepper's state (`state_arrays()`: parameters and optimiser state, `train_jax`/`train_torch`)
          and the array state of hooks that have one (a hook's `snapshot_state()` -> (meta, arrays),
          `restore_snapshot(meta, arrays)`: the scouts' tail losses, the held-out tracker's rows);
  meta    the next step, whether the loop has ended, the wall and step seconds so far, each member's log,
          failure, liveness and steps done, and the spike guards' history and skip counts.

Files: `<folder>/<phase>.json` (the meta, with the training's key, the phase, the sha256 of the arrays
file and a checksum of itself) and `<folder>/<phase>-<step>.npz` (the arrays), written atomically, the
arrays first; older arrays files of the phase are removed once the new JSON is in place. A snapshot whose
key, phase, member count, step count or checksums do not match is not used: the training starts over, with
a warning. `train_cached` keeps them in `OUT/trained/<framework>/<key>/inflight/` and removes them once the
finished training is stored. `phase(name)` gives the store of another phase of the same training (a
scouted run: "scouts", then "continuation").
"""
from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from lagbench.files import results as R

log = logging.getLogger("lagbench")

SNAPSHOT_EVERY_S = 300.0   # at most this much wall time of a training is lost to an interruption


class Snapshots:
    def __init__(self, folder, key: str, every_s: float | None = None, phase: str = "run"):
        self.folder, self.key, self.name = Path(folder), str(key), phase
        self.every_s = float(SNAPSHOT_EVERY_S if every_s is None else every_s)
        self._last = time.monotonic()

    def phase(self, name: str) -> Snapshots:
        return Snapshots(self.folder, self.key, self.every_s, name)

    def due(self) -> bool:
        return time.monotonic() - self._last >= self.every_s

    def _json(self) -> Path:
        return self.folder / f"{self.name}.json"

    def save(self, meta: dict, arrays: dict) -> None:
        """Write the snapshot; a failed write (the folder gone, a symlink) is a warning, never the end of the
        training it was to protect; a full disk stops the run (`results.DiskFull`), before hours of training
        end with nowhere to go."""
        self._last = time.monotonic()
        npz = f"{self.name}-{int(meta['step'])}.npz"
        try:
            if self.folder.is_symlink():
                raise OSError(f"{self.folder} is a symlink; snapshots are never written through one")
            digest = R.write_npz(self.folder / npz, arrays)
            record = R.json_lossless({**meta, "key": self.key, "phase": self.name, "arrays": npz, "arrays_sha256": digest})
            record["checksum"] = R.result_checksum(record)
            R.atomic_write_bytes(self._json(), json.dumps(record, sort_keys=True).encode())
            for old in self.folder.glob(f"{self.name}-*.npz"):
                if old.name != npz and not old.is_symlink():
                    old.unlink(missing_ok=True)
        except R.DiskFull:
            raise   # the run stops: the last snapshot written stays, and a resumed run starts from it
        except OSError as e:
            log.warning("training snapshot not written to %s (the training goes on): %s", self.folder, e)

    def load(self, members: int, steps: int) -> tuple[dict, dict] | None:
        """(meta, arrays) of the phase's snapshot, or None if there is none or it does not fit this run."""
        path = self._json()
        if not path.exists():
            return None
        try:
            meta = json.loads(R.read_nofollow(path))
            if meta.get("checksum") != R.result_checksum(meta):
                raise R.CorruptResult("checksum mismatch")
            expected = {"key": self.key, "phase": self.name, "members": members, "steps": steps}
            wrong = {k: meta.get(k) for k, v in expected.items() if meta.get(k) != v}
            if wrong:
                raise R.CorruptResult(f"made by another run ({wrong}, expected {expected})")
            npz = self.folder / meta["arrays"]
            if npz.is_symlink() or R.sha256_file(npz) != meta["arrays_sha256"]:
                raise R.CorruptResult(f"{npz.name}: missing or checksum mismatch")
            arrays = R.load_npz(npz)
        except (OSError, ValueError, KeyError, R.CorruptResult) as e:
            log.warning("training snapshot %s not used, starting over: %s", path, e)
            return None
        log.info("resuming a training from its snapshot at step %d (%s)", meta["step"], path)
        return meta, arrays

    def clear(self) -> None:
        """Remove this training's snapshot files (every phase) and the folder if it is then empty."""
        if not self.folder.is_dir() or self.folder.is_symlink():
            return
        for f in list(self.folder.glob("*.json")) + list(self.folder.glob("*.npz")):
            f.unlink(missing_ok=True)
        try:
            self.folder.rmdir()
        except OSError:
            pass
