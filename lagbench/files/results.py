"""Result files: atomic writes, checksums, and the unit layout of `docs/RESULTS.md`.

Every file is written to a temporary name in the same folder and renamed into place, so a killed
run never leaves a half-written file under a final name, and never through a symlink; files get the
umask's mode. These helpers (`atomic_write_bytes`, `read_nofollow`) are the only file writers of
`systems.cache` and `reports` too. A unit's `result.json` carries the sha256
of each of its other files and a checksum of itself (sha256 of the canonical JSON without the
"checksum" key: `json.dumps(d, sort_keys=True, separators=(",", ":"))`). `load_result` verifies
both and raises `CorruptResult` on any mismatch; the runner then reruns the unit.
"""
from __future__ import annotations

import errno
import hashlib
import io
import json
import math
import os
import stat
import tempfile
from pathlib import Path

import numpy as np

# the folder locks: `output_folder` takes one; every command runs inside `writing` (re-exported for callers)
from lagbench.files.folder_lock import _LOCKS, LOCK_NAME, lock, made, refuse_if_locked, writes, writing  # noqa: F401

SCHEMA = 1


class CorruptResult(Exception):
    """A result or cache file failed its checksum, or could not be parsed."""


def umask() -> int:
    """The process's umask (read without changing it where /proc allows)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    old = os.umask(0o022)
    os.umask(old)
    return old


FULL = (errno.ENOSPC, errno.EDQUOT)


class DiskFull(OSError):
    """No space (or no quota) left where a result was being written: `filename` names the file. A run
    stops at the first one (`replication.run.runner`), since every later unit would train for nothing."""


def atomic_write_bytes(path: Path, data: bytes, *, sync: bool = True) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder (fsync'd unless ``sync``
    is False) and a rename: never half-written, and a symlink at ``path`` is replaced, never written
    through. The file gets the mode a plain ``open`` would give (0666 less the umask; ``mkstemp``
    alone makes 0600)."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as e:
        raise (DiskFull(e.errno, e.strerror, str(path)) if e.errno in FULL else e) from e
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fchmod(fh.fileno(), 0o666 & ~umask())
            if sync:
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as e:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(e, OSError) and e.errno in FULL:
            raise DiskFull(e.errno, e.strerror, str(path)) from e
        raise


def read_nofollow(path) -> bytes:
    """The bytes of a regular file at ``path``, never through a symlink (OSError otherwise)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(fd, "rb") as fh:
        return fh.read()


def own_folder(path) -> bool:
    """Whether ``path`` is a real folder (not a symlink) of this user's that no one else may write: where the
    suite keeps what it will execute (its cache key, compiled code). OSError where it cannot be looked at."""
    st = os.lstat(path)
    return stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid() and not st.st_mode & 0o022


def make_own_folder(path) -> str | None:
    """Make ``path`` (mode 0700, parents too) and check it with `own_folder`: None where it is this user's own,
    else why it cannot be used (one line, for the caller's warning or error)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True, mode=0o700)
        if own_folder(path):
            return None
    except OSError as exc:
        return f"cannot make {path} ({exc})"
    return f"{path} is not a folder of this user's that no one else may write"


def output_folder(path, option: str = "--out") -> Path:
    """`path` as a folder this process can write into, created if absent, and locked for this process
    (`writing`); else a ValueError naming `option` (checked before any work starts, so no computation is
    lost to a bad output folder or to another command writing into it)."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{option} {path}: exists and is not a folder; give a folder path")
    try:
        if not path.exists():
            made(path)
        path.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ValueError(f"{option} {path}: cannot create the folder ({e.strerror or e})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise ValueError(f"{option} {path}: the folder is not writable; give a writable folder")
    lock(path, option)
    return path


def _clean(obj, keep_nan: bool = False):
    """JSON-safe: NumPy scalars to Python, NaN to None (kept as JSON `NaN` with `keep_nan`, for state read
    back by this suite only: training snapshots). +-inf stay (JSON `Infinity`, which Python and pandas read
    back): a diverged rollout's error is +inf, and a verdict must see it as such."""
    if isinstance(obj, dict):
        return {str(k): _clean(v, keep_nan) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v, keep_nan) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist(), keep_nan)
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and math.isnan(obj) and not keep_nan:
        return None
    return obj


def json_lossless(obj):
    """`obj` JSON-ready without loss: NumPy to Python, NaN and infinities kept (`NaN`, `Infinity`)."""
    return _clean(obj, keep_nan=True)


def canonical(d: dict) -> bytes:
    """The checksummed form of `d`: JSON with keys sorted at every level, no spaces, ASCII (`\\u` escapes),
    NaN and infinities as `NaN` / `Infinity` (json's defaults), encoded as UTF-8."""
    return json.dumps(d, sort_keys=True, separators=(",", ":")).encode()


def sha256_bytes(data: bytes) -> str:
    """sha256 of `data`, 64 lowercase hex digits."""
    return hashlib.sha256(data).hexdigest()


def sha256_file(path: Path) -> str:
    """sha256 of a file's bytes (read in 1 MiB blocks), 64 lowercase hex digits."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def result_checksum(d: dict) -> str:
    """The checksum a result.json carries: sha256 of `canonical` of `d` without its top-level "checksum"
    key (nested keys named so are kept)."""
    return sha256_bytes(canonical({k: v for k, v in d.items() if k != "checksum"}))


def write_json(path: Path, d: dict, *, checksum: bool = False) -> dict:
    d = _clean(d)
    if checksum:
        d["checksum"] = result_checksum(d)
    atomic_write_bytes(Path(path), json.dumps(d, indent=1, sort_keys=True).encode())
    return d


def read_json(path: Path) -> dict:
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise CorruptResult(f"{path}: cannot read JSON ({e})") from e


def write_csv(path: Path, df) -> str:
    buf = io.StringIO()
    df.to_csv(buf, index=False)
    data = buf.getvalue().encode()
    atomic_write_bytes(Path(path), data)
    return sha256_bytes(data)


def write_npz(path: Path, arrays: dict) -> str:
    buf = io.BytesIO()
    np.savez_compressed(buf, **{k: np.asarray(v) for k, v in arrays.items()})
    data = buf.getvalue()
    atomic_write_bytes(Path(path), data)
    return sha256_bytes(data)


def load_npz(path: Path) -> dict:
    try:
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    except Exception as e:  # zipfile/pickle/value errors all mean the file is unusable
        raise CorruptResult(f"{path}: cannot read arrays ({e})") from e


def unit_dir(out: Path, claim: str, framework: str, model: str, seed: int) -> Path:
    return Path(out) / "units" / claim / framework / model / f"seed{seed}"


def load_result(folder: Path) -> dict:
    """The verified result.json of a unit folder; CorruptResult if it or a listed file is bad."""
    folder = Path(folder)
    d = read_json(folder / "result.json")
    expected = d.get("checksum")
    if expected is None or result_checksum(d) != expected:
        raise CorruptResult(f"{folder / 'result.json'}: checksum mismatch")
    for name, digest in (d.get("files") or {}).items():
        f = folder / name
        if not f.exists() or sha256_file(f) != digest:
            raise CorruptResult(f"{f}: missing or checksum mismatch")
    return d


def is_finished(folder: Path) -> bool:
    try:
        load_result(folder)
        return True
    except CorruptResult:
        return False
