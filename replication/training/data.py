"""Training and held-out data for a protocol, in NumPy float64, shared by both frameworks.

A *recipe* (`RECIPES[name]`) turns (system, n, rng) into a batch dict of float64 arrays:
  "q", "qdot"  the model's two inputs, (N, dof); for canonical coordinates "qdot" holds p
  "extra"      optional extra inputs (N, e): a per-sample field strength, or q-double-dot for an
               inverse-dynamics model
  "target"     what the model must predict, (N, k)
  "weight"     optional per-sample loss weight (N,)
  "qddot"      the true acceleration (N, dof), kept for evaluation
  "h", "scale" a window's frame step and scale (N, 1), with `protocol.trajectory_loss` (whose "target" is then
               the window's scaled displacements: `replication.fit.windows`)
  "q_taps", "qdot_taps"  each row's neighbouring frames (N, T*dof), with `protocol.filter_loss`
               (`replication.fit.filter_rows`)
`BatchStream` draws the pools and the batch order once from the seed, so the JAX and the PyTorch
loop given the same protocol and seed see the same batches in the same order. With `data.resample` a pool is
drawn every epoch; the state entries `data.fixed` names are those of the epoch-0 draw in every epoch.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from lagbench import systems
from lagbench.replication.training.protocol_parts import HELDOUT_SEED  # noqa: F401  (data.HELDOUT_SEED)
from lagbench.systems.arm_data import ARMS  # arm recipes by name


@lru_cache(maxsize=32)
def _system(name: str, params: tuple):
    return systems.get(name, **dict(params))


def _states(name, params, n, rng):
    s = _system(name, params)
    st = s.sample_states(n, rng)
    return s, st


def _with_coords(s, st, protocol, qddot, extra=None, weight=None):
    q, qdot = st["q"], st["qdot"]
    out = {"qddot": qddot}
    if protocol.task == "hamiltonian":
        if protocol.data.coords == "qp":
            kw = {k: v for k, v in st.items() if k not in ("q", "qdot")}
            p = s.canonical_momentum(q, qdot, backend="numpy", **kw)
            pdot = _pdot(s, q, qdot, qddot, kw)
            out.update(q=q, qdot=p, target=np.concatenate([qdot, pdot], -1))
        else:  # deliberately non-canonical: treat qdot as if it were the momentum
            out.update(q=q, qdot=qdot, target=np.concatenate([qdot, qddot], -1))
    else:
        out.update(q=q, qdot=qdot, target=qddot)
    if extra is not None:
        out["extra"] = extra
    if weight is not None:
        out["weight"] = weight
    return out


def _pdot(s, q, qdot, qddot, kw):
    """dp/dt along the true motion, exact: dL/dq (+ generalised forces), from `systems`. (A central
    difference of p broke down near the speed of light: 0.47 % of relativistic targets came out 0.)"""
    return s.canonical_momentum_rate(q, qdot, backend="numpy", **kw)


def targets_version(protocol) -> str:
    """What changed in a protocol's targets since its results were first cached ("" = nothing): part of
    the training cache key, so a model trained on old targets is never reused."""
    if protocol.task == "hamiltonian" and protocol.data.coords == "qp":
        return "pdot-exact"
    if protocol.data.recipe.startswith("two_link_arm") and arm_trajectories(protocol.data.n_train) > protocol.data.n_train // ARM_POINTS:
        return f"arm-min-{ARM_MIN_TRAJECTORIES}-trajectories"
    return ""


# An arm pool of n samples: n // ARM_POINTS trajectories, at least ARM_MIN_TRAJECTORIES (each at least 2
# points). A small pool is a few points along several trajectories, not one trajectory: one covers a
# corner of the state space that no model can generalise from (measured, quick, 3 seeds: DeLaN and the FF
# net on 256 samples of one trajectory had torque MSE 64 and 63 on the family's held-out states, above the
# null predictor's 34.7; on 8 trajectories of 32 points, 3.9 and 5.0 with the same 2000 steps).
ARM_POINTS, ARM_MIN_TRAJECTORIES = 200, 8


def arm_trajectories(n: int) -> int:
    return max(min(ARM_MIN_TRAJECTORIES, n // 2), n // ARM_POINTS, 1)


def sample_inputs(states: dict, system_params) -> list:
    """The per-sample system inputs of drawn `states` (e.g. the relativistic field g) that `system_params`
    does not fix, in the order the models see them as extra inputs."""
    fixed = dict(system_params)
    return sorted(k for k in states if k not in ("q", "qdot") and k not in fixed)


def recipe_iid(protocol, n, rng, held=None):
    """i.i.d. states from the system's declared distribution, exact targets. held: state entries (n, ...) that
    replace the drawn ones before the targets are computed (`Data.fixed`, from `held_states`)."""
    name = protocol.data.recipe.removesuffix("_iid")
    params = tuple(sorted(protocol.data.system_params))
    s, st = _states(name, params, n, rng)
    if held:
        st = {**st, **held}
    kw = {k: st[k] for k in sample_inputs(st, params)}
    st = {k: v for k, v in st.items() if k in ("q", "qdot") or k in kw}
    qddot = s.acceleration(st["q"], st["qdot"], backend="numpy", **kw)
    extra = np.stack([kw[k] for k in sorted(kw)], -1) if kw else None
    weight = None
    if protocol.loss == "l1_gamma":
        weight = 1.0 + 1.0 / np.sqrt(1.0 - np.sum(st["qdot"] ** 2, -1))
    return _with_coords(s, st, protocol, qddot, extra=extra, weight=weight)


def recipe_arm(protocol, n, rng, kind="train"):
    """An arm's inverse dynamics along smooth trajectories (the recipe names the arm: `two_link_arm`, or
    `four_joint_arm`): inputs q, qdot, extra=qddot, target tau, each (n, dof)."""
    from lagbench.systems.datasets import arm_dataset

    n_traj = arm_trajectories(n)
    arm = next(a for a in ARMS if protocol.data.recipe.startswith(a))
    other = {} if arm == "two_link_arm" else {"system": arm}   # the two-link arm's cache keys as they are
    d = arm_dataset(kind=kind, n_traj=n_traj, n_points=-(-n // n_traj), seed=int(rng.integers(2**31)), **other)
    dof = np.asarray(d["q"]).shape[-1]
    q, qdot, qddot, tau = (np.asarray(d[k]).reshape(-1, dof)[:n] for k in ("q", "qdot", "qddot", "tau"))
    return {"q": q, "qdot": qdot, "extra": qddot, "target": tau, "qddot": qddot}


RECIPES = {"iid": recipe_iid, "arm": recipe_arm}


def recipe_file(protocol, n, rng, kind="train"):
    """A user's data file (see `lagbench.files.user_data`): the train or held-out rows, as a batch dict; with
    `protocol.trajectory_loss`, the training rows are windows of the recording (`replication.fit.windows`); with
    `protocol.filter_loss`, rows with their neighbouring frames (`replication.fit.filter_rows`)."""
    from lagbench.files.user_data import split_rows

    ref = protocol.data.recipe.removeprefix("file:")
    if protocol.trajectory_loss is not None and kind == "train":
        from lagbench.replication.fit.windows import training_windows

        return training_windows(ref, protocol.trajectory_loss, protocol.loss)
    if protocol.filter_loss is not None and kind == "train":
        from lagbench.replication.fit.filter_rows import training_rows

        return training_rows(ref, protocol.filter_loss)
    return split_rows(ref, protocol.task, kind)


def recipe_for(protocol):
    if protocol.data.recipe.startswith("file:"):
        return recipe_file
    if protocol.data.recipe.endswith("_iid"):
        return recipe_iid
    if protocol.data.recipe.startswith(ARMS):
        return recipe_arm
    raise ValueError(f"unknown data recipe {protocol.data.recipe!r}; valid: <system>_iid, {', '.join(ARMS)}")


def heldout(protocol, seed: int = HELDOUT_SEED, **kw) -> dict:
    """The fixed held-out set of a protocol (the same for every seed and model): the draw of generator
    `seed` (`replication.run.splits`: the development draw unless a test run's evaluation asks for its own);
    a user's file: its held-out rows."""
    if protocol.data.recipe.startswith("file:"):
        kw = {"kind": "heldout", **kw}
    return recipe_for(protocol)(protocol, protocol.data.n_heldout, np.random.default_rng(seed), **kw)


def held_states(protocol, n, rng) -> dict:
    """The entries `protocol.data.fixed` names of the system's n states drawn from rng (ValueError for a name
    the system does not draw)."""
    params = tuple(sorted(protocol.data.system_params))
    _, st = _states(protocol.data.recipe.removesuffix("_iid"), params, n, rng)
    unknown = sorted(set(protocol.data.fixed) - set(st))
    if unknown:
        raise ValueError(f"data fixed {', '.join(unknown)}: not a state the system draws; valid: {', '.join(sorted(st))}")
    return {k: st[k] for k in protocol.data.fixed}


class BatchStream:
    """Batches for step k of a protocol and seed: `stream.batch(k) -> dict of float64 arrays`."""

    def __init__(self, protocol, seed: int):
        self.p = protocol
        self.seed = int(seed)
        self.per_epoch = protocol.data.n_train // protocol.batch
        self._epoch = None
        self._pool = None
        self._order = None
        self._fixed = None
        self._held = None

    def _load_epoch(self, epoch):
        if self.p.data.resample or self._fixed is None:
            rng = np.random.default_rng([self.seed, 7919, epoch if self.p.data.resample else 0])
            kw = {}
            if self.p.data.fixed:   # the epoch-0 draw's entries (its generator), in every epoch
                if self._held is None:
                    self._held = held_states(self.p, self.p.data.n_train, np.random.default_rng([self.seed, 7919, 0]))
                kw["held"] = self._held
            self._pool = recipe_for(self.p)(self.p, self.p.data.n_train, rng, **kw)
            if not self.p.data.resample:
                self._fixed = self._pool
        self._order = np.random.default_rng([self.seed, 104729, epoch]).permutation(self.p.data.n_train)
        self._epoch = epoch

    def batch(self, step: int) -> dict:
        epoch, i = divmod(int(step), self.per_epoch)
        if epoch != self._epoch:
            self._load_epoch(epoch)
        idx = self._order[i * self.p.batch:(i + 1) * self.p.batch]
        return {k: v[idx] for k, v in self._pool.items()}
