"""Authenticated on-disk cache for generated source text and NumPy datasets.

Location: ``$LAGBENCH_CACHE`` (default ``.cache/`` under the current directory), subfolders
``codegen/`` and ``datasets/``. The folder is not trusted: every entry carries an HMAC-SHA256 of its
kind, name (a hash of everything it is derived from) and content under the user's private key
(``systems.cache_key``), so only entries this user's lagbench wrote are ever read, and generated
code is executed only from those. A checksum stored beside a file would authenticate nothing: anyone
able to plant the file can recompute it. A file that fails verification (planted, edited, truncated,
unreadable, a symlink, made by an older version) is reported by ``load_*`` as missing (``None``) and
logged at INFO level, so callers regenerate and overwrite it. Without a private key nothing is loaded
or stored. Writes are atomic (temporary file + ``os.replace``, which replaces a symlink rather than
following it), safe for concurrent processes, with the mode the umask allows. A cache that cannot be
written (read-only, full, a file where its folder belongs) is warned about once per folder and skipped:
the caller goes on with what it computed in memory.

- ``load_text(kind, name) -> str | None``, ``store_text(kind, name, text)``
- ``load_arrays(name) -> dict[str, np.ndarray] | None``, ``store_arrays(name, arrays)``
- ``digest(*parts) -> str``: SHA-256 hex of the parts' ``repr``, for cache keys.
"""

from __future__ import annotations

import hashlib
import logging
import os
from pathlib import Path

import numpy as np

from lagbench.files.results import atomic_write_bytes, read_nofollow  # light: NumPy only
from lagbench.systems import cache_key

log = logging.getLogger(__name__)

_HEADER = "# lagbench-cache hmac-sha256="
_CHECKSUM_KEY = "__hmac_sha256__"


def cache_dir(kind: str) -> Path:
    root = Path(os.environ.get("LAGBENCH_CACHE") or ".cache")
    return root / kind


def digest(*parts) -> str:
    return hashlib.sha256("\x1f".join(repr(p) for p in parts).encode()).hexdigest()


def text_path(kind: str, name: str) -> Path:
    return cache_dir(kind) / f"{name}.py"


_UNWRITABLE: set = set()   # cache folders already warned about


def _store(path: Path, data: bytes) -> Path | None:
    """Write an entry; where the cache cannot be written (read-only, full, not a folder) the caller goes on
    with what it computed in memory, after one warning per folder naming it: the cache only saves time."""
    try:
        atomic_write_bytes(path, data, sync=False)
        return path
    except OSError as e:
        if str(path.parent) not in _UNWRITABLE:
            _UNWRITABLE.add(str(path.parent))
            log.warning("the cache folder %s cannot be written (%s); going on without storing there (set "
                        "LAGBENCH_CACHE to a writable folder to keep what is computed)", path.parent,
                        e.strerror or e)
        return None


def store_text(kind: str, name: str, text: str) -> Path | None:
    tag = cache_key.tag(kind, name, text.encode())
    if tag is None:
        return None
    return _store(text_path(kind, name), f"{_HEADER}{tag}\n{text}".encode())


def load_text(kind: str, name: str) -> str | None:
    path = text_path(kind, name)
    if not os.path.lexists(path):
        return None
    try:
        raw = read_nofollow(path).decode()
        header, _, body = raw.partition("\n")
        if not header.startswith(_HEADER):
            raise ValueError("no authentication header")
        if not cache_key.verify(kind, name, body.encode(), header[len(_HEADER) :]):
            raise ValueError("not written by this user's lagbench (authentication failed)")
        return body
    except (OSError, UnicodeDecodeError, ValueError) as err:
        log.info("cache entry %s is not trusted (%s); regenerating", path, err)
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


def store_arrays(name: str, arrays: dict) -> Path | None:
    import io

    arrays = {k: np.asarray(v) for k, v in arrays.items()}
    tag = cache_key.tag("datasets", name, _array_checksum(arrays).encode())
    if tag is None:
        return None
    buf = io.BytesIO()
    np.savez(buf, **arrays, **{_CHECKSUM_KEY: np.array(tag)})
    return _store(array_path(name), buf.getvalue())


def load_arrays(name: str) -> dict | None:
    import io

    path = array_path(name)
    if not os.path.lexists(path):
        return None
    try:
        with np.load(io.BytesIO(read_nofollow(path)), allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        stored = str(arrays.pop(_CHECKSUM_KEY))
        if not cache_key.verify("datasets", name, _array_checksum(arrays).encode(), stored):
            raise ValueError("not written by this user's lagbench (authentication failed)")
        return arrays
    except Exception as err:  # any unreadable or inconsistent file is regenerated, never trusted
        log.info("cached dataset %s is corrupt (%s); regenerating", path, err)
        return None
