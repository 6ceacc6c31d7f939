"""A user's function named on the command line: "module:function" (a module importable from the working
folder) or "path/to/file.py:function". Imported only when the user names it."""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path


def import_function(ref: str, option: str):
    """The callable `ref` names; a ValueError naming `option` and `ref` when it cannot be imported."""
    module, sep, attr = str(ref).rpartition(":")
    if not sep or not module or not attr:
        raise ValueError(f"{option} {ref}: give module:function (or path/to/file.py:function)")
    try:
        if module.endswith(".py"):
            path = Path(module).resolve()
            if not path.is_file():
                raise ImportError(f"no file {module}")
            spec = importlib.util.spec_from_file_location(f"lagbench_user_{path.stem}", path)
            mod = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(mod)
        else:
            cwd = str(Path.cwd())
            added = cwd not in sys.path
            if added:   # the console script's sys.path starts at its own folder, not the working one
                sys.path.insert(0, cwd)
            try:
                mod = importlib.import_module(module)
            finally:
                if added:
                    sys.path.remove(cwd)
        fn = getattr(mod, attr)
    except (ImportError, AttributeError, ValueError, SyntaxError) as e:
        raise ValueError(f"{option} {ref}: cannot import it ({e}); give module:function, importable from "
                         f"the working folder, or path/to/file.py:function") from None
    if not callable(fn):
        raise ValueError(f"{option} {ref}: {attr} is not a function")
    return fn
