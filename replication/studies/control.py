"""Closed-loop tracking control of the two-link arm with a learned inverse model (the DeLaN paper's experiment).

Computed-torque control: tau = tau_hat(q_d, qdot_d, qddot_d) + KP (q_d - q) + KD (qdot_d - qdot), at
`RATE` Hz with the torque held over each control period (zero-order hold). The plant is the SymPy ground
truth (`systems.get(system)`, forward dynamics under the torque; `system` one of `systems.arm_data.ARMS`,
default `SYSTEM`, the two-link arm) integrated by RK4 with `SUBSTEPS` steps per period in float64,
independent of the controller. A batch of reference trajectories is tracked side by side from the
reference's own initial state; a trajectory whose state leaves `DIVERGED` is marked diverged and scores no
error.

References the models never trained on: the "test" family of `systems.arm_data` (other shapes, higher
frequencies) and the training family played twice as fast ("train_x2": q_d(2t), so velocities x 2 and
accelerations x 4). Controllers: each learned inverse model of claim 9 trained on the full data set
(`delan`, `ff`; every framework and seed in the results folder), the true inverse dynamics (the best a
model can give) and PD alone (tau_hat = 0, the null controller). Gains are fixed and declared (`KP`,
`KD`; `gains(dof)` the same on every joint of an arm of `dof` joints), low enough that the feed-forward term
has to do most of the work, as in the paper.

`hold(plant, q, v, tau, h)` is the plant over one control period, `period(plant, h, ...)` the same as one
compiled program for long tracks (the online study's too, `online.py`);
`track(inverse, refs, ...) -> dict` simulates one controller; `tracking_table(controllers, ...) ->
(DataFrame, traces)` runs controllers (name, framework, seed, inverse) on every family of an arm;
`control_study(results, ...)` runs claim 9's models and the two references on the two-link arm;
`write_study(results, folder)` (`lagbench control`, into RESULTS/control) writes FOLDER/tracking.csv (one
row per controller, framework, seed and family: tracking MSE per joint and overall, torque effort, diverged
count, ratio to PD alone) and FOLDER/traces.npz (the first reference of each family and each controller's
first-seed response) for the report. The four-joint arm's study, which fits its own models, is
`arm4_control.py`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

RATE = 500.0             # control ticks per second
SUBSTEPS = 4             # plant RK4 steps per control period
SYSTEM = "two_link_arm"  # the plant unless a study names another arm
KP_GAIN = 20.0


def gains(dof: int) -> tuple[np.ndarray, np.ndarray]:
    """KP, KD (dof,): KP_GAIN on every joint, KD = 2 sqrt(KP) (critically damped for a unit inertia)."""
    kp = np.full(int(dof), KP_GAIN)
    return kp, 2.0 * np.sqrt(kp)


KP, KD = gains(2)   # the two-link arm's
DURATION = 4.0           # seconds per reference
N_REFS = 8
SEED = 2000              # the references' generator seed: no training or held-out draw of claim 9 uses it
DIVERGED = 1e3
MODELS = ("delan", "ff")
FAMILIES = ("test", "train_x2")


def references(family: str, n: int = N_REFS, duration: float = DURATION, rate: float = RATE, seed: int = SEED,
               system: str = SYSTEM):
    """q_d, qdot_d, qddot_d (n, T, dof) of arm `system` at the control ticks, and t (T,)."""
    from lagbench.systems.arm_data import arm_dataset

    fast = family == "train_x2"
    k = 2.0 if fast else 1.0
    base = "train" if fast else family
    n_t = int(round(duration * rate)) + 1
    d = arm_dataset(base, n_traj=n, n_points=n_t, seed=seed, duration=k * duration, cache=False, system=system)
    return {"t": d["t"] / k, "q": d["q"], "qdot": d["qdot"] * k, "qddot": d["qddot"] * k * k}


def hold(plant, q, v, tau, h: float, substeps: int = SUBSTEPS):
    """The plant over one control period under the held torque: `substeps` RK4 steps of h seconds on (B, dof)
    float64 states. Returns q, v at the period's end and the acceleration at its start (what the plant does
    under tau at the tick: the measured q-double-dot of an online learner's sample)."""
    def f(q_, v_):
        return v_, plant.acceleration(q_, v_, tau=tau)

    a0 = None
    for _ in range(substeps):   # RK4 under the held torque
        k1 = f(q, v)
        a0 = k1[1] if a0 is None else a0
        k2 = f(q + 0.5 * h * k1[0], v + 0.5 * h * k1[1])
        k3 = f(q + 0.5 * h * k2[0], v + 0.5 * h * k2[1])
        k4 = f(q + h * k3[0], v + h * k3[1])
        q = q + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return q, v, a0


COMPILE_FROM = 256   # periods: a shorter track steps its plant in NumPy (compiling costs 1-9 s), a longer one compiled
_COMPILED = {}


def period(plant, h: float, substeps: int = SUBSTEPS, periods: int = COMPILE_FROM):
    """`hold` as a function (q, v, tau) -> (q, v, a0) of NumPy arrays. For a SymPy system (`systems.System`)
    or a plant that says it traces (`traceable`: its `acceleration` takes backend="jax", a robustness scene's)
    and a track of at least `COMPILE_FROM` periods it is one compiled JAX program in float64 (the same RK4
    through the plant's JAX backend: a period of the four-joint arm about 27x, of the two-link arm about 10x
    faster than NumPy's 16 calls; the states agree to rounding, `tests/replication/studies/test_control.py`),
    kept per plant by its repr, which names what it simulates; any other plant and short tracks run `hold`
    in NumPy."""
    from lagbench.systems.system import System

    if not (isinstance(plant, System) or getattr(plant, "traceable", False)) or periods < COMPILE_FROM:
        return lambda q, v, tau: hold(plant, q, v, tau, h, substeps)
    import jax

    key = (repr(plant), float(h), int(substeps))
    if key not in _COMPILED:
        class _Jax:   # the plant through its JAX backend, for `hold` to trace
            @staticmethod
            def acceleration(q, v, tau):
                return plant.acceleration(q, v, backend="jax", tau=tau)

        _COMPILED[key] = jax.jit(lambda q, v, tau: hold(_Jax, q, v, tau, h, substeps))
    fn, cpu = _COMPILED[key], jax.devices("cpu")[0]   # the ground truth on the CPU, as in NumPy, on a machine with a GPU too

    def step(q, v, tau):
        with jax.default_device(cpu):
            out = fn(np.asarray(q, np.float64), np.asarray(v, np.float64), np.asarray(tau, np.float64))
            return tuple(np.array(x) for x in out)   # writable NumPy copies: the loops assign into them
    return step


def diverged(q, v):
    """(B,) bool: a state (q, v) (B, dof) that is not finite or has left `DIVERGED`."""
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(q).all(-1) | ~np.isfinite(v).all(-1) | (np.abs(np.c_[q, v]) > DIVERGED).any(-1)


def track(inverse, refs: dict, rate: float = RATE, substeps: int = SUBSTEPS, kp=None, kd=None, plant=None,
          system: str = SYSTEM) -> dict:
    """Simulate the closed loop for every reference at once. `inverse(q, qdot, qddot) -> tau` on (B, dof)
    float64 arrays, or None for PD alone; `plant` anything with `.acceleration(q, qdot, tau=)` (default the
    SymPy arm `system`); kp, kd default `gains(dof)`. Returns q, tau (B, T, dof) and a diverged mask (B,)."""
    from lagbench import systems

    plant = plant or systems.get(system)
    qd, vd, ad = refs["q"], refs["qdot"], refs["qddot"]
    b, n_t, dof = qd.shape
    kp = gains(dof)[0] if kp is None else kp
    kd = gains(dof)[1] if kd is None else kd
    q, v = qd[:, 0].copy(), vd[:, 0].copy()
    h = 1.0 / rate / substeps
    qs, taus = np.zeros((b, n_t, dof)), np.zeros((b, n_t, dof))
    bad = np.zeros(b, bool)
    step = period(plant, h, substeps, n_t - 1)

    for i in range(n_t):
        qs[:, i] = q
        ff = np.zeros((b, dof)) if inverse is None else np.asarray(inverse(qd[:, i], vd[:, i], ad[:, i]), float)
        tau = ff + kp * (qd[:, i] - q) + kd * (vd[:, i] - v)
        tau[bad] = 0.0
        taus[:, i] = tau
        if i == n_t - 1:
            break
        with np.errstate(over="ignore", invalid="ignore"):   # a diverging state is caught below
            q, v, _ = step(q, v, tau)
        bad |= diverged(q, v)
        q[bad], v[bad] = qd[bad, i + 1], vd[bad, i + 1]   # parked on the reference; scored as diverged
    return {"q": qs, "tau": taus, "diverged": bad}


def scores(sim: dict, refs: dict) -> dict:
    ok = ~sim["diverged"]
    err = (sim["q"] - refs["q"])[ok]
    out = {"n_refs": int(len(ok)), "n_diverged": int((~ok).sum())}
    if ok.any():
        for j in range(err.shape[-1]):
            out[f"track_mse_joint{j}"] = float(np.mean(err[..., j] ** 2))
        out["track_mse"] = float(np.mean(np.sum(err ** 2, -1)))
        out["torque_effort"] = float(np.mean(np.sum(sim["tau"][ok] ** 2, -1)))
    return out


def _learned(results) -> list:
    """(model, framework, seed, Fitted) for every usable full-data claim-9 unit in the results folder."""
    from pathlib import Path

    from lagbench.replication.fit.load import load_fitted

    out = []
    for model in MODELS:
        for folder in sorted(Path(results).glob(f"units/delan_arm/*/{model}/seed*")):
            if (folder / "result.json").is_file() and (folder / "checkpoint.npz").is_file():
                try:
                    out.append((model, folder.parent.parent.name, folder.name.removeprefix("seed"), load_fitted(folder)))
                except ValueError:
                    continue   # a failed or damaged unit: no controller
    return out


def references_controllers(system: str = SYSTEM) -> list:
    """(name, framework, seed, inverse) of the true inverse dynamics of arm `system` and PD alone."""
    from lagbench import systems

    plant = systems.get(system)
    return [("exact", "numpy", "-", lambda q, v, a: plant.inverse_dynamics(q, v, a)), ("pd", "numpy", "-", None)]


def control_study(results, families=FAMILIES, n_refs: int = N_REFS, duration: float = DURATION,
                  progress=None) -> tuple[pd.DataFrame, dict]:
    """Claim 9's learned inverse models in RESULTS on the two-link arm, beside `references_controllers`."""
    controllers = references_controllers() + [(m, fw, seed, fitted.inverse_dynamics)
                                              for m, fw, seed, fitted in _learned(results)]
    return tracking_table(controllers, families, n_refs, duration, progress=progress)


def tracking_table(controllers, families=FAMILIES, n_refs: int = N_REFS, duration: float = DURATION,
                   system: str = SYSTEM, progress=None) -> tuple[pd.DataFrame, dict]:
    """Every controller (name, framework, seed, inverse) on `n_refs` references of each family of arm
    `system`: the tracking table (one row per family and controller, with ratio_to_pd: `controllers` must
    hold "pd") and the traces (each family's first reference and each controller's first-seed response)."""
    rows, traces = [], {}
    for family in families:
        refs = references(family, n_refs, duration, system=system)
        traces[f"{family}__t"], traces[f"{family}__q_ref"] = refs["t"], refs["q"][0]
        for name, fw, seed, inverse in controllers:
            sim = track(inverse, refs, system=system)
            rows.append({"family": family, "controller": name, "framework": fw, "seed": seed, **scores(sim, refs)})
            key = f"{family}__{name}__{fw}"
            if key + "__q" not in traces:
                traces[key + "__q"], traces[key + "__tau"] = sim["q"][0], sim["tau"][0]
            if progress:
                progress(f"{family} {name} {fw} {seed}")
    df = pd.DataFrame(rows)
    pd_mse = df[df["controller"] == "pd"].set_index("family")["track_mse"]
    df["ratio_to_pd"] = df["track_mse"] / df["family"].map(pd_mse)
    return df, traces


def write_study(results, folder, **kw) -> pd.DataFrame:
    from pathlib import Path

    from lagbench.files import results as R

    folder = Path(folder)
    df, traces = control_study(results, **kw)
    R.write_csv(folder / "tracking.csv", df)
    R.write_npz(folder / "traces.npz", traces)
    return df
