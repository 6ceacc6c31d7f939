"""Writing and reading files safely: atomic replacement with the umask's mode, and no symlinks followed.

- ``atomic_write(path, data, sync=False)``: temporary file in the same folder, then ``os.replace``, so
  a killed process never leaves a half-written file under its final name, and a symlink at ``path``
  is replaced, never written through. The file gets 0666 less the umask, as ``open`` would give
  (``mkstemp`` alone makes 0600). Used by ``systems.cache`` and ``replication.results``.
- ``read_nofollow(path) -> bytes``: OSError if ``path`` is a symlink.
- ``umask() -> int``.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


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


def atomic_write(path: Path, data: bytes, *, sync: bool = False) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename, with the
    mode a plain ``open`` would give (0666 less the umask; ``mkstemp`` alone makes 0600)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fchmod(fh.fileno(), 0o666 & ~umask())
            if sync:
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def read_nofollow(path) -> bytes:
    """The bytes of a regular file at ``path``, never through a symlink (OSError otherwise)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(fd, "rb") as fh:
        return fh.read()
