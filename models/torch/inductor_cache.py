"""Where inductor writes: the generated C++, its shared objects and AOTInductor's packages, for every
PyTorch compile path of the suite (training's torch.compile, `replication.training.compile_torch`; the
ahead-of-time libraries of `models.torch.compiled`; the speed study's compiled training step).

    private() -> bool          point inductor at `$LAGBENCH_CACHE/torchinductor`; False where it cannot be had
    scratch(prefix) -> path    a temporary folder inside it, removed on exit (AOTInductor's package files)

Inductor's default is `/tmp/torchinductor_<user>`, outside the folders the suite is given, and it loads
the shared objects it finds in its cache: so the folder must be this user's own. It is created mode 0700
and used only if it is a real directory (not a symlink) owned by this user that no one else may write;
otherwise `private()` says False and the caller compiles nothing (training goes on eager; an AOT compile
raises `InductorCacheError`, which the speed study records as the row's failure). A TORCHINDUCTOR_CACHE_DIR
already set in the environment is the user's choice and is kept.
"""
from __future__ import annotations

import contextlib
import logging
import os
import tempfile
from pathlib import Path

from lagbench.files.results import make_own_folder
from lagbench.systems.cache import cache_dir

log = logging.getLogger("lagbench")

ENV = "TORCHINDUCTOR_CACHE_DIR"


class InductorCacheError(RuntimeError):
    """No private folder for inductor's generated code: nothing may be compiled."""


def private() -> bool:
    """Point inductor's cache at this user's own folder; False (with a warning) where none can be had."""
    if os.environ.get(ENV):
        return True
    folder = cache_dir("torchinductor")
    why = make_own_folder(folder)
    if why:
        log.warning("torch compiling off: inductor's cache: %s", why)
        return False
    os.environ[ENV] = str(folder.resolve())
    return True


@contextlib.contextmanager
def scratch(prefix: str):
    """A temporary folder inside inductor's private cache, removed on exit; InductorCacheError without one."""
    if not private():
        raise InductorCacheError(f"no private folder for inductor's generated code under {cache_dir('torchinductor')}"
                                 " (see the log); set LAGBENCH_CACHE to a folder of your own")
    root = Path(os.environ[ENV])
    root.mkdir(parents=True, exist_ok=True, mode=0o700)
    with tempfile.TemporaryDirectory(prefix=prefix, dir=root) as tmp:
        yield Path(tmp)
