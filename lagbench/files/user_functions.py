"""The one boundary with a user's code: a function named on the command line, "module:function" (a module
importable from the working folder) or "path/to/file.py:function", and every call into it (`--add-model`'s
factory and module, `--predict`'s and `--energy`'s function). Imported only when the user names it.

`import_function(ref, option)`: the callable; a ValueError naming `option` and `ref` when it cannot be imported.
A module named without a path is imported with the working folder first on sys.path (one imported before from
another file than the one found now is imported anew); a file given by its path
runs with its own folder first, so the modules beside it import (an exception while either runs is a
`UserCodeError`, as below). A module
named without a path whose top-level name is the suite's package (`SUITE`, "lagbench") while the working folder
holds a file or package of that name is refused, naming the collision: the suite's own would be imported.
Every other name is free: the suite installs nothing else at the top level.

`call(option, ref, what, fn, *args, **kwargs)`: fn's result; any exception it raises becomes a `UserCodeError`:
one line naming the option and reference, the call (`what`), the user's file and line and the exception, and
whether a rerun can help (an error in the user's code: it cannot; memory, files or network: it may). Its
`details` hold the user's part of the traceback (shown with `lagbench -v`).
`wrong(option, ref, message)`: the `UserCodeError` of a value the user's code returned that the suite cannot
use (a shape, a type).
`array_of(option, ref, what, out, shape=None)`: the user's output as a float64 array (of `shape`), else a
UserCodeError.
`nonfinite_rows(out) -> int`: rows of an (N, ...) output with any non-finite entry; `nonfinite_failure(k, n)`:
a result's failure record when k of n held-out states got a non-finite prediction (None when k is 0).
`is_users(error)`: whether an error line is a UserCodeError's (the command line says no rerun retries it).
`time_limit(seconds, error)`: a block (one call into a user's code) under a limit of `seconds` (None: none); past
it, `error()` (a UserCodeError) is raised: at once where a timer can interrupt the call (SIGALRM, in the main
thread; the timer's exception is a BaseException, so the user's `except Exception` lets it through), else when
the call returns.
"""
from __future__ import annotations

import contextlib
import importlib
import importlib.util
import inspect
import os
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

SUITE = "lagbench"   # the suite's one top-level package
NO_RERUN = "an error in your code: a rerun fails the same way until it is fixed"
MAY_RERUN = "a rerun may help once its cause (memory, files, network) is gone"
TRANSIENT = (MemoryError, ConnectionError, TimeoutError)


class UserCodeError(ValueError):
    """A user's code raised, or returned what the suite cannot use. `details`: the user's traceback (or "");
    `rerun`: whether running the same command again can help."""

    def __init__(self, message: str, details: str = "", rerun: bool = False):
        super().__init__(message)
        self.details, self.rerun = details, rerun

    def __reduce__(self):   # it crosses to and from worker processes whole
        return UserCodeError, (self.args[0], self.details, self.rerun)


def wrong(option: str, ref: str, message: str) -> UserCodeError:
    return UserCodeError(f"{option} {ref}: {message}; {NO_RERUN}")


def is_users(error: str) -> bool:
    return NO_RERUN in error or MAY_RERUN in error


def _collision(module: str, option: str, ref: str) -> None:
    top = module.split(".")[0]
    if top != SUITE:
        return
    cwd = Path.cwd()
    mine = [p for p in (cwd / f"{top}.py", cwd / top / "__init__.py") if p.is_file()]
    suite = Path(__file__).resolve().parents[1]   # the lagbench package's own folder
    if mine and mine[0].parent.resolve() != suite:
        raise ValueError(f"{option} {ref}: {mine[0].relative_to(cwd)} in the working folder has the name of the "
                         f"suite's package {top!r}: the suite's would be imported instead; "
                         f"give its path ({mine[0].relative_to(cwd)}:{ref.rpartition(':')[2]}) or rename it")


def _load_file(path: Path):
    """The module of the file at `path`, run with its folder first on sys.path (its neighbours import)."""
    spec = importlib.util.spec_from_file_location(f"lagbench_user_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    folder = str(path.parent)
    sys.path.insert(0, folder)
    try:
        spec.loader.exec_module(mod)
    finally:
        sys.path.remove(folder)
    return mod


def _forget_stale(top: str) -> None:
    """Drops the imported module `top` (and its submodules) when the working folder's sys.path now finds
    `top` in another file than the one imported: a name is read from where it is found today."""
    if top == SUITE or top not in sys.modules:
        return
    held = {k: sys.modules.pop(k) for k in list(sys.modules) if k == top or k.startswith(top + ".")}
    try:
        found = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        found = None
    was = getattr(held[top], "__file__", None)
    if found is not None and found.origin and was and Path(found.origin).resolve() == Path(was).resolve():
        sys.modules.update(held)


def import_function(ref: str, option: str):
    """The callable `ref` names; a ValueError naming `option` and `ref` when it cannot be imported."""
    module, sep, attr = str(ref).rpartition(":")
    if not sep or not module or not attr:
        raise ValueError(f"{option} {ref}: give module:function (or path/to/file.py:function)")
    if not module.endswith(".py"):
        _collision(module, option, ref)
    try:
        if module.endswith(".py"):
            path = Path(module).resolve()
            if not path.is_file():
                raise ImportError(f"no file {module}")
            mod = call(option, ref, f"importing {module}", _load_file, path, files=(str(path),))
        else:
            cwd = str(Path.cwd())
            sys.path.insert(0, cwd)   # the console script's sys.path starts at its own folder, not the working one
            try:
                _forget_stale(module.split(".")[0])
                found = importlib.util.find_spec(module)
                if found is None:
                    raise ImportError(f"no module named {module!r}")
                mod = call(option, ref, f"importing {module}", importlib.import_module, module, files=(found.origin,))
            finally:
                sys.path.remove(cwd)
        fn = getattr(mod, attr)
    except UserCodeError:
        raise
    except (ImportError, AttributeError, ValueError, SyntaxError) as e:
        raise ValueError(f"{option} {ref}: cannot import it ({e}); give module:function, importable from "
                         f"the working folder, or path/to/file.py:function") from None
    if not callable(fn):
        raise ValueError(f"{option} {ref}: {attr} is not a function")
    return fn


def source_file(obj) -> str | None:
    """The file that defines a function, a class or an instance's class (the file of its first method), or None."""
    target = obj if inspect.isroutine(obj) or inspect.isclass(obj) else type(obj)
    codes = [getattr(v, "__code__", None) for v in vars(target).values()] if inspect.isclass(target) else \
        [getattr(inspect.unwrap(target), "__code__", None) or getattr(getattr(target, "__func__", None), "__code__", None)]
    return next((c.co_filename for c in codes if c is not None), None)


def _shown(path: str) -> str:
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _same(a: str, files) -> bool:
    return any(f and os.path.realpath(a) == os.path.realpath(f) for f in files)


def call(option: str, ref: str, what: str, fn, *args, files=(), **kwargs):
    """fn(*args, **kwargs); an exception it raises is a UserCodeError (see the module's doc). `files`: the user's
    files to point at in the traceback, or a function giving them, called only on an error (default: the file that
    defines fn)."""
    try:
        return fn(*args, **kwargs)
    except UserCodeError:
        raise
    except Exception as e:  # noqa: BLE001 - any exception of a user's code is reported the same way
        files = tuple(files() if callable(files) else files) or (source_file(fn),)
        frames = traceback.extract_tb(e.__traceback__)
        mine = [i for i, f in enumerate(frames) if _same(f.filename, files)]
        if mine:
            f = frames[mine[-1]]
            where = f"{_shown(f.filename)} line {f.lineno}, in {f.name}"
        else:
            where = f"defined in {_shown(files[0])}" if files[0] else "no file of yours in the traceback"
        text = str(e).strip().splitlines()
        exc = f"{type(e).__name__}: {text[0]}{' ...' if len(text) > 1 else ''}" if text else type(e).__name__
        rerun = isinstance(e, TRANSIENT) or type(e).__name__ == "OutOfMemoryError"
        details = ("Traceback (your code):\n" + "".join(traceback.format_list(frames[mine[0]:] if mine else []))
                   + "".join(traceback.format_exception_only(type(e), e)))
        raise UserCodeError(f"{option} {ref}: {what} raised {exc} ({where}); {MAY_RERUN if rerun else NO_RERUN}",
                            details, rerun) from None


def array_of(option: str, ref: str, what: str, out, shape: tuple | None = None):
    """`out` as a float64 NumPy array (of `shape` unless None); a UserCodeError naming what came back otherwise."""
    import numpy as np

    try:
        arr = np.asarray(out, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise wrong(option, ref, f"{what} returned {type(out).__name__}, not an array of numbers ({e})") from None
    if shape is not None and arr.shape != tuple(shape):
        raise wrong(option, ref, f"{what} returned shape {arr.shape}, expected {tuple(shape)}")
    return arr


def nonfinite_rows(out) -> int:
    import numpy as np

    out = np.asarray(out, dtype=np.float64)
    return int(np.sum(~np.all(np.isfinite(out.reshape(out.shape[0], -1)), axis=1))) if out.ndim else int(not np.isfinite(out))


def nonfinite_failure(k: int, n: int) -> dict | None:
    """The failure of a result whose predictions were non-finite on k of its n held-out states."""
    if k == 0:
        return None
    return {"kind": "non_finite_prediction", "step": None, "message": f"non-finite on {k} of {n} held-out states"}


class _PastLimit(BaseException):
    """Raised into a user's call by `time_limit`'s timer."""


@contextlib.contextmanager
def time_limit(seconds: float | None, error):
    if seconds is None:
        yield
        return
    timer = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if timer and 0 < signal.getitimer(signal.ITIMER_REAL)[0] < seconds:
        timer = False   # a timer of the caller's runs out first: it is left alone, the call checked when it returns
    if timer:
        def alarm(signum, frame):
            raise _PastLimit
        old = signal.signal(signal.SIGALRM, alarm)
        previous = signal.setitimer(signal.ITIMER_REAL, seconds)
    t0 = time.perf_counter()
    try:
        try:
            yield
        finally:
            if timer:
                signal.setitimer(signal.ITIMER_REAL, 0)
    except _PastLimit:
        raise error() from None
    finally:
        if timer:
            signal.signal(signal.SIGALRM, old)
            if previous[0] > 0:   # a caller's timer goes on with what it had left
                signal.setitimer(signal.ITIMER_REAL, max(previous[0] - (time.perf_counter() - t0), 1e-6), previous[1])
    if time.perf_counter() - t0 > seconds:   # a call the timer could not interrupt
        raise error()
