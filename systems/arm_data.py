"""Torque datasets for the arms (DeLaN): smooth joint trajectories, exact torques.

``arm_dataset(kind="train", n_traj=16, n_points=200, seed=0, *, duration=4.0, cache=True,
system="two_link_arm", **params) -> dict`` of float64 arrays: "t" (n_points,), "q", "qdot", "qddot",
"tau" (n_traj, n_points, dof) and "energy" (n_traj, n_points); ``system`` is an arm, one of ``ARMS``
("two_link_arm", dof 2; "four_joint_arm", dof 4), with parameter overrides ``params``.

Each joint follows q_j(t) = c_j + sum_k a_jk sin(2 pi f_jk t + phi_jk), so q, qdot, qddot are
analytic; tau = ``inverse_dynamics(q, qdot, qddot)`` of ``systems.get(system, **params)``.
The two families differ in shape, so "test" probes extrapolation:

- "train": 3 components per joint, frequencies U[0.2, 0.7) Hz, amplitudes U[0.2, 0.6) / k
  (decaying with the component index k = 1..3), offsets c ~ U[-pi/2, pi/2);
- "test": 2 components per joint in a higher band, frequencies U[0.8, 1.3) Hz, equal
  amplitudes U[0.3, 0.5), offsets c ~ U[-pi/4, pi/4) (faster motions, larger velocities and
  accelerations than anything in "train").

Every arm draws its coefficients in the same order (trajectory, joint, component); the cache key names
the system (``systems.dataset_cache``), so each arm's datasets are cached apart.
"""

from __future__ import annotations

import numpy as np

FAMILIES = {
    "train": {"k": 3, "f": (0.2, 0.7), "a": (0.2, 0.6), "decay": True, "c": np.pi / 2},
    "test": {"k": 2, "f": (0.8, 1.3), "a": (0.3, 0.5), "decay": False, "c": np.pi / 4},
}
ARMS = ("two_link_arm", "four_joint_arm")


def _trajectories(kind: str, n_traj: int, dof: int, t: np.ndarray, rng: np.random.Generator):
    fam = FAMILIES[kind]
    k = fam["k"]
    f = rng.uniform(*fam["f"], (n_traj, dof, k))
    a = rng.uniform(*fam["a"], (n_traj, dof, k))
    if fam["decay"]:
        a = a / np.arange(1, k + 1)
    phi = rng.uniform(0.0, 2 * np.pi, (n_traj, dof, k))
    c = rng.uniform(-fam["c"], fam["c"], (n_traj, dof))
    w = 2 * np.pi * f
    arg = w[:, None] * t[None, :, None, None] + phi[:, None]  # (B, T, dof, k)
    q = c[:, None] + np.sum(a[:, None] * np.sin(arg), axis=-1)
    qdot = np.sum((a * w)[:, None] * np.cos(arg), axis=-1)
    qddot = -np.sum((a * w**2)[:, None] * np.sin(arg), axis=-1)
    return q, qdot, qddot


def arm_dataset(kind: str = "train", n_traj: int = 16, n_points: int = 200, seed: int = 0, *,
                duration: float = 4.0, cache: bool = True, system: str = "two_link_arm", **params) -> dict:
    """Trajectory family ``kind`` ("train" | "test") of arm ``system`` with exact torques; see the module
    docstring."""
    from lagbench.systems.dataset_cache import _key, cached
    from lagbench.systems.registry import get

    if kind not in FAMILIES:
        raise ValueError(f"unknown arm trajectory family {kind!r}; valid: {', '.join(FAMILIES)}")
    if n_traj < 1 or n_points < 2 or duration <= 0:
        raise ValueError("arm_dataset needs n_traj >= 1, n_points >= 2 and duration > 0")
    if system not in ARMS:
        raise ValueError(f"arm_dataset: unknown arm {system!r}; valid: {', '.join(ARMS)}")
    s = get(system, **params)

    def make():
        t = np.linspace(0.0, float(duration), int(n_points))
        q, qdot, qddot = _trajectories(kind, int(n_traj), s.dof, t, np.random.default_rng(seed))
        tau = s.inverse_dynamics(q, qdot, qddot)
        return {"t": t, "q": q, "qdot": qdot, "qddot": qddot, "tau": tau, "energy": s.energy(q, qdot)}

    key = _key("arm", s, family=kind, n_traj=int(n_traj), n_points=int(n_points), seed=int(seed),
               duration=float(duration))
    return cached(key, make, cache)
