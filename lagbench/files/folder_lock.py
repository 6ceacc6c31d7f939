"""One writer per output folder: an flock on the folder's `LOCK_NAME`, held by the command writing into it.

`lock(path, option)`: hold the folder's exclusive lock (released when this process lets go or ends); a
ValueError naming the holder if another process holds it. Reentrant within a process.
`refuse_if_locked(path, option)`: the same ValueError, asked before a command's long planning, so that a
second writer hears it at once; nothing is created or held.
`writing()`: the folders locked inside the block are let go at its end; one the command created (`made`) and
left holding only its lock file, because the block failed, is removed; `writes(fn)`: `fn` run inside it.
Every command, and every library call that writes a folder, runs in one: two commands never write into one
folder at once.
"""
from __future__ import annotations

import functools
import os
from contextlib import contextmanager
from pathlib import Path

from lagbench.files.clock import now

LOCK_NAME = ".lagbench.lock"
_LOCKS: dict = {}   # resolved folder -> the open lock file this process holds on it
_MADE: dict = {}    # resolved folder -> the folders this process created for it (`made`), itself first


def _busy(fd: int, path: Path, option: str) -> ValueError:
    """The error naming the process that holds the folder (read from its lock file)."""
    holder = os.read(fd, 200).decode("utf-8", "replace").strip() or "another process"
    return ValueError(f"{option} {path}: another lagbench command is writing into this folder ({holder}); "
                      "wait for it to end, or give another folder")


def lock(path: Path, option: str) -> None:
    import fcntl

    key = str(path.resolve())
    if key in _LOCKS:
        return
    try:
        fd = os.open(path / LOCK_NAME, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
    except OSError as e:
        raise ValueError(f"{option} {path}: cannot make its lock file {LOCK_NAME} ({e.strerror or e})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        err = _busy(fd, path, option)
        os.close(fd)
        raise err from None
    os.ftruncate(fd, 0)
    os.write(fd, f"pid {os.getpid()}, since {now()}".encode())
    _LOCKS[key] = fd


def refuse_if_locked(path, option: str = "--out") -> None:
    import fcntl

    path = Path(path)
    if path.is_symlink() or not (path / LOCK_NAME).is_file() or str(path.resolve()) in _LOCKS:
        return
    try:
        fd = os.open(path / LOCK_NAME, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return   # unreadable: `output_folder` says why when the command takes the folder
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        raise _busy(fd, path, option) from None
    finally:
        os.close(fd)


@contextmanager
def writing():
    before = set(_LOCKS)
    failed = True
    try:
        yield
        failed = False
    finally:
        for key in set(_LOCKS) - before:
            fd, folders = _LOCKS.pop(key), _MADE.pop(key, [])
            if failed:
                _unmake(key, folders)
            os.close(fd)


def made(path: Path) -> None:
    """Notes that this process creates the folder `path` (and the parents it lists), so that a command that
    fails before writing into it leaves no folder behind (`writing`)."""
    _MADE[str(path.resolve())] = [str(p.resolve()) for p in (path, *path.parents) if not p.exists()]


def _unmake(key: str, folders: list) -> None:
    """Removes a folder this process created, and its created parents, where it holds nothing but its lock
    file (a command refused before it wrote): a refused command leaves the file system as it found it."""
    if not folders:
        return
    try:
        if os.listdir(key) == [LOCK_NAME]:
            os.unlink(os.path.join(key, LOCK_NAME))
        for folder in folders:
            os.rmdir(folder)
    except OSError:
        pass   # something else is there now: it stays


def writes(fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with writing():
            return fn(*args, **kwargs)
    return wrapper
