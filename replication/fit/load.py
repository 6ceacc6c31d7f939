"""A model `lagbench fit` trained, loaded back: `load_fitted(DIR, framework=None) -> Fitted`.

DIR is a fit's unit folder (`OUT/units/fit/<framework>/<model>/seed<k>/`, holding result.json and
checkpoint.npz) or a results folder holding exactly one such unit (`fitted_folders` lists them all).
The result and checkpoint are verified against their checksums first (`results.load_result`); a failed
or damaged fit is refused with a ValueError naming the folder. The parameters are framework-neutral, so
a fit trained in JAX loads in PyTorch and back (`framework`, default the one it was trained in).

`Fitted` takes and returns float64 NumPy arrays of shape (N, dof) (through `replication.evaluation.adapters`):
  acceleration(q, qdot, tau=None)  q-double-dot. An LNN, HNN (its dH/dy at y = qdot) or baseline
                                   trained on accelerations; DeLaN's forward model M^-1 (tau - c - g)
                                   (tau = 0 when None). An inverse-dynamics baseline has none (ValueError).
  inverse_dynamics(q, qdot, qddot) tau, for a model trained on torques (DeLaN: M qddot + c + g; the
                                   baseline: its prediction); any other raises a ValueError.
  energy(q, qdot) -> (N,) or None  the model's own energy: DeLaN 1/2 qdot^T M qdot + V; HNN H(q, qdot);
                                   LNN qdot . dL/dqdot - L, with qdot . dL/dqdot = d/ds L(q, s qdot) at s = 1
                                   by a central difference (step ENERGY_STEP in s); a baseline has none (None).
                                   Evaluated in float64 with the same parameters (exactly the trained
                                   float32 function, without float32 round-off: in float32 the round-off of an
                                   LNN's L, whose offset is arbitrary, swamped the drift it was to measure).
  rollout(z0, t, dt, tau=None, progress=None)
                                   the model's motion from z0 = (q, qdot) over the times t, in its own
                                   framework (`replication.evaluation.rollout_native`).
  spec, protocol, task, framework, folder, result, and `model`: the adapter (`Padded`: any batch size, a few
  compiled shapes) with all the kind's methods (mass_matrix, coriolis, gravity, lagrangian, hamiltonian, ...).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lagbench.files import results as R
from lagbench.models import ModelSpec
from lagbench.models.kinds import CAPABILITIES
from lagbench.replication.evaluation.adapters import adapter, padded_size
from lagbench.replication.evaluation.rollout_native import native_rollout
from lagbench.replication.training.protocol import Protocol

ENERGY_STEP = 1e-4   # in float64: truncation ~1e-8 relative, round-off ~1e-12 x |L|


class Padded:
    """An adapter whose methods take any batch size N and run on N padded (with copies of the first row) to
    the next power of two: a JIT-compiled framework compiles a handful of shapes instead of one per N (the
    rollouts, one-step sets and energies of an evaluation each have their own); rows never mix, so the
    first N rows of the result are exactly the unpadded call's."""

    def __init__(self, model):
        self._model = model

    @property
    def native(self):
        """The framework model itself (`models.jax.build` / `models.torch.build`)."""
        return self._model.model

    def __getattr__(self, name):
        method = getattr(self._model, name)

        def call(*args):
            n = next(len(a) for a in args if a is not None)
            size = padded_size(n)
            pad = [None if a is None else np.concatenate([a, np.repeat(np.asarray(a)[:1], size - n, 0)])
                   for a in args]
            out = method(*pad)
            return tuple(o[:n] for o in out) if isinstance(out, tuple) else out[:n]
        return call


def fitted_folders(path) -> list[Path]:
    """The fit unit folders at `path`: itself if it holds a result.json, else those under units/fit/."""
    path = Path(path)
    if (path / "result.json").is_file():
        return [path]
    found = sorted(p.parent for p in (path / "units" / "fit").glob("*/*/seed*/result.json")
                   if not p.parent.name.startswith("superseded-"))
    if not found:
        raise ValueError(f"--model {path}: holds no fitted model (no result.json, nor units/fit/*/*/seed*/); give "
                         f"a folder written by `lagbench fit`")
    return found


@dataclass
class Fitted:
    spec: ModelSpec
    protocol: Protocol
    framework: str
    folder: Path
    result: dict
    model: object
    params: dict   # the parameters (the float64 copy that `energy` uses is built from them)

    @property
    def task(self) -> str:
        return self.protocol.task

    def one_step(self, rows: dict) -> tuple[dict, np.ndarray]:
        """(the batch of `rows` for this model's task, the model's prediction of its target on it)."""
        from lagbench.files import user_data
        from lagbench.replication.training.objective import predict

        b = user_data.batch_of(rows, self.task)
        return b, predict(self.model, self.spec.kind, self.task, b, np.concatenate)

    def acceleration(self, q, qdot, tau=None):
        if self.task == "hamiltonian":
            return self.model.time_derivative(q, qdot, None)[1]
        if self.task == "inverse_dynamics" and self.spec.kind != "delan":
            raise ValueError(f"{self.folder}: an inverse-dynamics {self.spec.kind} predicts torques only; it has "
                             f"no forward model (fit delan for both)")
        return self.model.acceleration(q, qdot, tau if self.spec.kind == "delan" else None)

    def rollout(self, z0, t, dt, tau=None, progress=None):
        """z (B, T, 2 dof): the model's motion from z0 = (q, qdot) (B, 2 dof) over the times t (T,) by the
        shared RK4 in steps of at most dt, in the model's framework (`rollout_native`); an HNN by its own
        flow on (q, qdot), DeLaN under the torques tau (B, T, dof) at the times t (interpolated linearly)."""
        if tau is not None and self.spec.kind != "delan":
            raise ValueError(f"{self.folder}: only DeLaN has a forward model under torques")
        if self.task == "inverse_dynamics" and self.spec.kind != "delan":
            self.acceleration(z0[:, :1], z0[:, :1])   # the ValueError saying why it has no forward model
        field = "time_derivative" if self.task == "hamiltonian" else "acceleration"
        return native_rollout(self.framework, self.model.native, self.spec.dtype, field, z0, t, dt, forcing=tau,
                              progress=progress)

    def inverse_dynamics(self, q, qdot, qddot):
        if self.task != "inverse_dynamics":
            raise ValueError(f"{self.folder}: this {self.spec.kind} was trained on accelerations without torques; it "
                             f"has no inverse dynamics")
        if self.spec.kind == "delan":
            return self.model.inverse_dynamics(q, qdot, qddot)
        return self.model.acceleration(q, qdot, qddot)

    @property
    def has_energy(self) -> bool:
        return self.spec.kind in CAPABILITIES and CAPABILITIES[self.spec.kind].energy

    def energy(self, q, qdot):
        kind = self.spec.kind
        if not self.has_energy:
            return None
        if not hasattr(self, "_model64"):
            spec64 = dataclasses.replace(self.spec, dtype="float64")
            self._model64 = Padded(adapter(self.framework, spec64, self.params))
        model = self._model64
        if kind == "delan":
            m = model.mass_matrix(q)
            return 0.5 * np.einsum("ni,nij,nj->n", qdot, m, qdot) + model.potential(q)
        if kind == "hnn":
            return model.hamiltonian(q, qdot, None)
        if kind == "lnn":
            h = ENERGY_STEP
            lag = model.lagrangian
            p_dot_qdot = (lag(q, (1 + h) * qdot, None) - lag(q, (1 - h) * qdot, None)) / (2 * h)
            return p_dot_qdot - lag(q, qdot, None)
        return None


def load_fitted(path, framework: str | None = None) -> Fitted:
    folders = fitted_folders(path)
    if len(folders) > 1:
        raise ValueError(f"{path}: holds {len(folders)} fitted models; give one of their folders: "
                         + ", ".join(str(f) for f in folders))
    folder = folders[0]
    try:
        result = R.load_result(folder)
    except R.CorruptResult as e:
        raise ValueError(f"{folder}: not a usable fit ({e})") from None
    if result.get("status") != "ok":
        why = (result.get("failure") or {}).get("message", "status " + str(result.get("status")))
        raise ValueError(f"{folder}: this fit failed ({why}); fit it again")
    if "checkpoint.npz" not in (result.get("files") or {}):
        raise ValueError(f"{folder}: has no checkpoint.npz; not a trained model")
    spec = ModelSpec.from_dict(result["model_spec"])
    framework = framework or result["framework"]
    params = R.load_npz(folder / "checkpoint.npz")
    return Fitted(spec, Protocol.from_dict(result["protocol"]), framework, folder, result,
                  Padded(adapter(framework, spec, params)), params)
