"""The user's private secret that authenticates cache entries (``systems.cache``).

The cache folder can be anywhere (default ``.cache/`` under the current directory), so its files are
not trusted: whoever controls that folder (a cloned repository, an unpacked archive, a shared disk)
can plant a file with whatever checksum it likes, and generated code from the cache is executed. So
each entry carries an HMAC-SHA256 of its kind, name and content under a 32-byte secret made once per
user and kept where only this user can read or write it:

- folder ``$XDG_CACHE_HOME/lagbench/`` (default ``~/.cache/lagbench/``), created mode 0700;
- file ``key`` in it, mode 0600, made with ``os.urandom`` and linked into place atomically.

Both must be owned by this user and be no symlinks; no one else may write the folder or read or
write the key (a folder made by someone else or a key of another mode is refused, not repaired); otherwise
``tag`` returns None, ``systems.cache`` neither loads nor stores anything, and all code and data are
regenerated in memory (one warning). The folder named by ``$LAGBENCH_CACHE`` plays no part here, so
pointing the cache at an untrusted place costs regeneration, never code execution.

- ``key_dir() -> Path``; ``tag(kind, name, data) -> str | None``; ``verify(kind, name, data, t) -> bool``
"""

from __future__ import annotations

import functools
import hashlib
import hmac
import logging
import os
import stat
import tempfile
from pathlib import Path

from lagbench.files.results import make_own_folder

log = logging.getLogger(__name__)


def key_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "lagbench"


def _private(st: os.stat_result, want, others: int = 0o077) -> bool:
    return want(st.st_mode) and st.st_uid == os.getuid() and not st.st_mode & others


def _read_key(path: Path) -> bytes | None:
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except FileNotFoundError:
        return None
    with os.fdopen(fd, "rb") as fh:
        if not _private(os.fstat(fh.fileno()), stat.S_ISREG):
            raise PermissionError(f"{path} is not a private file of this user (mode 0600)")
        data = fh.read()
    if len(data) != 32:
        raise PermissionError(f"{path} is not a 32-byte key")
    return data


@functools.lru_cache(maxsize=4)
def _key(folder: str) -> bytes | None:
    d = Path(folder)
    try:
        why = make_own_folder(d)
        if why:
            raise PermissionError(why)
        path = d / "key"
        found = _read_key(path)
        if found is None:
            fd, tmp = tempfile.mkstemp(dir=d, prefix=".key.")  # mode 0600
            try:
                with os.fdopen(fd, "wb") as fh:
                    fh.write(os.urandom(32))
                try:
                    os.link(tmp, path)  # atomic; a concurrent process's key wins
                except FileExistsError:
                    pass
            finally:
                os.unlink(tmp)
            found = _read_key(path)
        return found
    except OSError as err:
        log.warning("lagbench: no private cache key (%s); generated code and data are not cached", err)
        return None


def tag(kind: str, name: str, data: bytes) -> str | None:
    """HMAC-SHA256 (hex) binding ``data`` to its cache kind and name; None without a private key."""
    key = _key(str(key_dir()))
    if key is None:
        return None
    return hmac.new(key, f"{kind}\x00{name}\x00".encode() + data, hashlib.sha256).hexdigest()


def verify(kind: str, name: str, data: bytes, expected: str) -> bool:
    actual = tag(kind, name, data)
    return actual is not None and hmac.compare_digest(actual, expected)
