"""The dataset cache: a key from everything a dataset depends on, and load-or-make through `systems.cache`.

`_key(kind, system, **spec)` names a dataset by its kind, the system (name, options, parameters, the
definition's fingerprint) and the generating spec; `cached(key, make)` loads it or makes and stores it.
Raise `DATASET_VERSION` when a generator changes what it makes.
"""
from __future__ import annotations

import numpy as np

from lagbench.systems import cache as _cache
from lagbench.systems.system import System

DATASET_VERSION = "1"


def _key(kind: str, system: System, **spec) -> str:
    parts = (DATASET_VERSION, kind, system.name, sorted(system.options.items()),
             sorted(system.params.items()), system.definition.fingerprint(), sorted(spec.items()))
    return f"{kind}-{system.name}-{_cache.digest(*parts)[:24]}"


def cached(key: str, make, use_cache: bool = True) -> dict:
    """Load ``key`` from the dataset cache, or ``make()`` it and store it."""
    if use_cache:
        found = _cache.load_arrays(key)
        if found is not None:
            return found
    data = {k: np.asarray(v, dtype=np.float64) for k, v in make().items()}
    if use_cache:
        _cache.store_arrays(key, data)
    return data
