"""Seeded, cached datasets with exact targets (float64 NumPy).

- ``iid_dataset(name, n, seed, /, *, distribution="default", **system_kwargs)``: n i.i.d.
  states from the system's distribution (``System.sample_states``) with exact targets. Returns
  "q", "qdot", "qddot" (n, dof), "energy" (n,) and any per-sample parameter (n,) (relativistic:
  "g"). ``name``, ``n`` and ``seed`` are positional-only, so ``n=`` in ``system_kwargs`` is the
  wave's grid size: ``iid_dataset("wave", 1000, 0, n=100)``.
- ``trajectory_dataset(name, n_traj, t, seed, *, distribution="default", solver="dopri8",
  rtol=1e-12, atol=1e-12, **system_kwargs)``: initial states from the distribution integrated
  with ``systems.trajectories.integrate``. Returns "t" (T,), "q", "qdot", "qddot" (B, T, dof),
  "energy" (B, T) and per-sample parameters (B,).
- ``arm_dataset`` (re-exported from ``systems.arm_data``): the arms' torque datasets (two_link_arm,
  four_joint_arm).

Every dataset is written once to ``$LAGBENCH_CACHE/datasets/`` as .npz, keyed by a hash of
everything that defines it (kind, system, options, parameters, seed, sizes, the Lagrangian's
fingerprint); a corrupt file is detected by its checksum and regenerated (``systems.cache``).
Pass ``cache=False`` to skip the disk.
"""

from __future__ import annotations

import numpy as np

from lagbench.systems import cache as _cache
from lagbench.systems.arm_data import arm_dataset
from lagbench.systems.dataset_cache import DATASET_VERSION, _key, cached
from lagbench.systems.registry import get
from lagbench.systems.trajectories import integrate

_STATE_KEYS = ("q", "qdot")


def iid_dataset(name: str, n: int, seed: int, /, *, distribution: str = "default",
                cache: bool = True, **system_kwargs) -> dict:
    """n i.i.d. states of ``name`` with exact accelerations and energies (see module docstring)."""
    s = get(name, **system_kwargs)

    def make():
        states = s.sample_states(int(n), np.random.default_rng(seed), distribution)
        per_sample = {k: v for k, v in states.items() if k not in _STATE_KEYS}
        q, qdot = states["q"], states["qdot"]
        return {**states, "qddot": s.acceleration(q, qdot, **per_sample),
                "energy": s.energy(q, qdot, **per_sample)}

    key = _key("iid", s, n=int(n), seed=int(seed), distribution=distribution)
    return cached(key, make, cache)


def trajectory_dataset(name: str, n_traj: int, t, seed: int, *, distribution: str = "default",
                       solver: str = "dopri8", rtol: float = 1e-12, atol: float = 1e-12,
                       cache: bool = True, **system_kwargs) -> dict:
    """n_traj ground-truth trajectories of ``name`` on the grid ``t`` (see module docstring)."""
    s = get(name, **system_kwargs)
    ts = np.asarray(t, dtype=np.float64)

    def make():
        states = s.sample_states(int(n_traj), np.random.default_rng(seed), distribution)
        per_sample = {k: v for k, v in states.items() if k not in _STATE_KEYS}
        q, qdot = integrate(s, states["q"], states["qdot"], ts, rtol=rtol, atol=atol, solver=solver,
                            **per_sample)
        bcast = {k: v[:, None] for k, v in per_sample.items()}
        return {"t": ts, "q": q, "qdot": qdot, "qddot": s.acceleration(q, qdot, **bcast),
                "energy": s.energy(q, qdot, **bcast), **per_sample}

    key = _key("traj", s, n_traj=int(n_traj), t=_cache.digest(ts.tobytes()), seed=int(seed),
               distribution=distribution, solver=solver, rtol=float(rtol), atol=float(atol))
    return cached(key, make, cache)


__all__ = ["iid_dataset", "trajectory_dataset", "arm_dataset", "cached", "DATASET_VERSION"]
