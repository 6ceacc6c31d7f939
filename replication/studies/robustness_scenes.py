"""The robustness study's scenes: two-link arms that break DeLaN's assumptions, their data and their plant.

A `Scene` is one violation at one magnitude (`SCENES`, units in `UNITS`):

- "nominal": the SymPy `two_link_arm` as claim 9 has it: exact torques, no friction, no noise;
- "viscous": joint friction tau_f = b qdot (N m s/rad), the arm's own `friction` parameter;
- "coulomb": smooth Coulomb friction tau_c = c tanh(qdot / `V_S`) on each joint (N m; `V_S` = 0.05 rad/s,
  the four-joint arm's smoothing speed). The two-link arm has no such parameter, so it is applied here:
  the recorded torque is the exact inverse dynamics plus tau_c (the motor also overcomes it) and the
  tracking plant subtracts it from the applied torque (`Plant`);
- "torque_noise": Gaussian noise of standard deviation s (N m) on every recorded torque, iid per sample
  and joint; the plant itself is the nominal arm;
- "sensor_noise": Gaussian noise of standard deviation s (rad) on every recorded q, and no qdot or qddot
  recorded: `lagbench fit` estimates them from the noisy q by the suite's Savitzky-Golay filter
  (`replication.fit.trajectories`, its default window 15 at the data's 50 Hz) and drops each trajectory's
  first and last 7 samples; the plant is the nominal arm.

`scene_data(scene, family, n_traj, n_points, seed, noise_seed=0) -> dict` (float64): "t" (T,), the true
"q", "qdot", "qddot", "tau" (the scene's plant's torques, noise free) (B, T, 2), and what a recording holds,
"q_rec", "tau_rec" (noise added where the scene has it). Trajectories are `systems.arm_data`'s family
`family` drawn with `seed`; the noise is drawn with `noise_seed` alone, so every model of a seed trains on
the same recording. `write_recording(d, path, scene)` writes the recording as a `lagbench fit` trajectory
file (.npz: traj, t, q, tau, with the exact qdot and qddot unless the scene has sensor noise); a file
already there with the same arrays is left untouched (the npz's bytes carry a time stamp, and the fits
made from it are keyed by its bytes, so a rerun reuses them).

`Plant(scene)`: `.acceleration(q, qdot, tau=..., backend=)` of the scene's arm on (B, 2) float64 arrays (the
ground-truth forward dynamics, with the scene's friction; "numpy" or "jax"), `.inverse_dynamics(q, qdot, qddot)` its exact
torques; `replication.studies.control.track(..., plant=Plant(scene))` tracks on it (on the nominal plant
the frictionless arm's numbers bit for bit: tests/replication/studies/test_robustness_scenes.py).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

V_S = 0.05   # rad/s, the Coulomb friction's smoothing speed (as systems/library/arm4.py's COULOMB_SPEED)
UNITS = {"nominal": "-", "viscous": "N m s/rad", "coulomb": "N m", "torque_noise": "N m", "sensor_noise": "rad"}
KINDS = tuple(k for k in UNITS if k != "nominal")


@dataclass(frozen=True)
class Scene:
    kind: str           # one of UNITS
    magnitude: float = 0.0

    def __post_init__(self):
        if self.kind not in UNITS:
            raise ValueError(f"unknown scene kind {self.kind!r}; valid: {', '.join(UNITS)}")
        if not self.magnitude >= 0 or (self.kind == "nominal") != (self.magnitude == 0):
            raise ValueError(f"scene {self.kind}: magnitude {self.magnitude} (nominal takes 0, the others > 0)")

    @property
    def id(self) -> str:
        return "nominal" if self.kind == "nominal" else f"{self.kind}-{self.magnitude:g}"

    def _of(self, kind) -> float:
        return float(self.magnitude) if self.kind == kind else 0.0

    friction = property(lambda self: self._of("viscous"))
    coulomb = property(lambda self: self._of("coulomb"))
    tau_noise = property(lambda self: self._of("torque_noise"))
    q_noise = property(lambda self: self._of("sensor_noise"))


SCENES = (Scene("nominal"), Scene("viscous", 0.5), Scene("viscous", 2.0), Scene("coulomb", 0.5),
          Scene("coulomb", 2.0), Scene("torque_noise", 0.5), Scene("torque_noise", 2.0),
          Scene("sensor_noise", 0.003), Scene("sensor_noise", 0.03))


def coulomb_torque(scene: Scene, qdot, xp=np):
    """The torque the joints' Coulomb friction takes, c tanh(qdot / V_S) (0 without it), in float64 of the
    array module `xp` (NumPy, or jax.numpy inside a compiled plant)."""
    return scene.coulomb * xp.tanh(xp.asarray(qdot, xp.float64) / V_S)


class Plant:
    """The scene's arm: the SymPy two-link arm with its viscous friction, and the Coulomb friction on top."""

    def __init__(self, scene: Scene):
        from lagbench import systems

        self.scene = scene
        self.arm = systems.get("two_link_arm", friction=scene.friction)

    traceable = True   # `acceleration(..., backend="jax")` traces: `control.period` compiles long tracks

    def __repr__(self) -> str:   # what it simulates (`control.period` keys its compiled programs by it)
        return f"Plant({self.scene!r})"

    def acceleration(self, q, qdot, tau, backend: str = "numpy"):
        if self.scene.coulomb:
            if backend == "numpy":
                tau = tau - coulomb_torque(self.scene, qdot)
            else:
                import jax.numpy as jnp

                tau = tau - coulomb_torque(self.scene, qdot, jnp)
        return self.arm.acceleration(q, qdot, backend=backend, tau=tau)

    def inverse_dynamics(self, q, qdot, qddot):
        return self.arm.inverse_dynamics(q, qdot, qddot) + coulomb_torque(self.scene, qdot)


def scene_data(scene: Scene, family: str, n_traj: int, n_points: int, seed: int, noise_seed: int = 0,
               duration: float = 4.0) -> dict:
    from lagbench.systems.arm_data import arm_dataset

    d = arm_dataset(family, n_traj=n_traj, n_points=n_points, seed=seed, duration=duration, cache=False,
                    friction=scene.friction)
    tau = d["tau"] + coulomb_torque(scene, d["qdot"])
    rng = np.random.default_rng([7919, int(noise_seed)])
    q_rec = d["q"] + scene.q_noise * rng.standard_normal(d["q"].shape) if scene.q_noise else d["q"]
    tau_rec = tau + scene.tau_noise * rng.standard_normal(tau.shape) if scene.tau_noise else tau
    return {"t": d["t"], "q": d["q"], "qdot": d["qdot"], "qddot": d["qddot"], "tau": tau, "q_rec": q_rec,
            "tau_rec": tau_rec}


def write_recording(d: dict, path, scene: Scene) -> None:
    from lagbench.files import results as R

    b, n_t, dof = d["q"].shape
    rows = {"traj": np.repeat(np.arange(b), n_t), "t": np.tile(d["t"], b), "q": d["q_rec"].reshape(-1, dof),
            "tau": d["tau_rec"].reshape(-1, dof)}
    if not scene.q_noise:   # exact derivatives; with sensor noise the fit estimates them from q
        rows.update(qdot=d["qdot"].reshape(-1, dof), qddot=d["qddot"].reshape(-1, dof))
    if Path(path).is_file():   # a file of the same arrays is kept as is: its bytes key the fits made from it
        with np.load(path) as z:
            if set(z.files) == set(rows) and all(np.array_equal(z[k], v) for k, v in rows.items()):
                return
    R.write_npz(path, rows)

