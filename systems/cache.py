"""Checksummed on-disk cache for generated source text and NumPy datasets.

Location: ``$LAGBENCH_CACHE`` (default ``.cache/`` under the current directory), subfolders
``codegen/`` and ``datasets/``. Every entry carries a SHA-256 of its content; a file that
fails verification (checksum mismatch, truncation, unreadable archive) is reported by
``load_*`` as missing (``None``) and logged at INFO level, so callers regenerate it. Writes are
atomic (temporary file + ``os.replace``), safe for concurrent processes.

- ``load_text(kind, name) -> str | None``, ``store_text(kind, name, text)``
- ``load_arrays(name) -> dict[str, np.ndarray] | None``, ``store_arrays(name, arrays)``
- ``digest(*parts) -> str``: SHA-256 hex of the parts' ``repr``, for cache keys.
"""

from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)

_HEADER = "# lagbench-cache sha256="
_CHECKSUM_KEY = "__sha256__"


def cache_dir(kind: str) -> Path:
    root = Path(os.environ.get("LAGBENCH_CACHE") or ".cache")
    return root / kind


def digest(*parts) -> str:
    return hashlib.sha256("\x1f".join(repr(p) for p in parts).encode()).hexdigest()


def _atomic_write(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def text_path(kind: str, name: str) -> Path:
    return cache_dir(kind) / f"{name}.py"


def store_text(kind: str, name: str, text: str) -> Path:
    path = text_path(kind, name)
    check = hashlib.sha256(text.encode()).hexdigest()
    _atomic_write(path, f"{_HEADER}{check}\n{text}".encode())
    return path


def load_text(kind: str, name: str) -> str | None:
    path = text_path(kind, name)
    if not path.exists():
        return None
    try:
        raw = path.read_bytes().decode()
        header, _, body = raw.partition("\n")
        if not header.startswith(_HEADER):
            raise ValueError("missing checksum header")
        if hashlib.sha256(body.encode()).hexdigest() != header[len(_HEADER) :]:
            raise ValueError("checksum mismatch")
        return body
    except (OSError, UnicodeDecodeError, ValueError) as err:
        log.info("cache entry %s is corrupt (%s); regenerating", path, err)
        return None


def _array_checksum(arrays: dict) -> str:
    h = hashlib.sha256()
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(f"{key}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def array_path(name: str) -> Path:
    return cache_dir("datasets") / f"{name}.npz"


def store_arrays(name: str, arrays: dict) -> Path:
    import io

    arrays = {k: np.asarray(v) for k, v in arrays.items()}
    buf = io.BytesIO()
    np.savez(buf, **arrays, **{_CHECKSUM_KEY: np.array(_array_checksum(arrays))})
    path = array_path(name)
    _atomic_write(path, buf.getvalue())
    return path


def load_arrays(name: str) -> dict | None:
    path = array_path(name)
    if not path.exists():
        return None
    try:
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        stored = str(arrays.pop(_CHECKSUM_KEY))
        if stored != _array_checksum(arrays):
            raise ValueError("checksum mismatch")
        return arrays
    except Exception as err:  # any unreadable or inconsistent file is regenerated, never trusted
        log.info("cached dataset %s is corrupt (%s); regenerating", path, err)
        return None
