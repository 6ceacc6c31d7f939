"""Closed-loop tracking control of the four-joint arm with a learned inverse model (a study beside the claims).

The two-link study (`control.py`) reads claim 9's trained models, which are two-link models. For the SymPy
four-joint arm (`systems.get("four_joint_arm")`) this study fits DeLaN and the feed-forward net itself, both
under one equal budget, the robustness study's (`robustness.budget`: `steps` Adam steps of batch 256 at a
constant 1e-3, claim 9's widths `robustness.HIDDEN` 64 x 64, softplus, torque MSE with weight decay 1e-5,
every row trained on), by `replication.fit.task.fit` (`robustness.fit_model`) on a recording of the arm's
training family (`systems.arm_data`, "train": `SIZES` 16 trajectories x 256 samples over 4 s, 4096 rows
as claim 9's quick pool, generator seed `TRAIN_SEED`, exact torques, written by
`robustness_scenes.write_recording` as a `lagbench fit` trajectory file). The seed is the initialisation's;
the data are the same for every seed.

Then the two-link study's loop runs on the four-joint plant: computed torque at `control.RATE` (500) Hz,
RK4 plant with `control.SUBSTEPS` steps a period, gains `control.gains(4)` (KP 20, KD 2 sqrt(20) on every
joint), the same reference families ("test", the unseen shapes, and "train_x2", the training family twice
as fast; generator seed `control.SEED`), with each fitted model, the arm's true inverse dynamics and PD
alone (`control.tracking_table`).

`write_study(folder, framework, seeds, steps, n_refs, duration, progress)` writes FOLDER/tracking.csv (the
two-link study's columns, with 4 joints), FOLDER/traces.npz (as the two-link study's), FOLDER/study.json
(the settings), the recording in FOLDER/data/ and the fits in FOLDER/fits/seed<k>/ (a rerun of the same
data and options reuses them: fit's own cache, and the recording's bytes are kept when its arrays are the
same).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from lagbench.replication.studies import control as C

SYSTEM = "four_joint_arm"
MODELS = ("delan", "ff")   # names of `robustness.MODELS`: DeLaN and the feed-forward net of (q, qdot, qddot)
STEPS = 3000               # the robustness study's budget: claim 9's quick protocol cut to run in minutes
SIZES = {"n_train": 16, "n_points": 256, "duration": 4.0}
TRAIN_SEED = 2001          # a development draw: no claim reads the four-joint arm's training family at it


def recording(folder, sizes=None) -> Path:
    """The training family's recording, FOLDER/data/train.npz (kept as is when its arrays are the same)."""
    from lagbench.replication.studies.robustness_scenes import Scene, write_recording
    from lagbench.systems.arm_data import arm_dataset

    z = {**SIZES, **(sizes or {})}
    d = arm_dataset("train", n_traj=z["n_train"], n_points=z["n_points"], seed=TRAIN_SEED,
                    duration=z["duration"], cache=False, system=SYSTEM)
    path = Path(folder) / "data" / "train.npz"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_recording({**d, "q_rec": d["q"], "tau_rec": d["tau"]}, path, Scene("nominal"))
    return path


def fitted_controllers(folder, framework: str = "jax", seeds=(0,), steps: int = STEPS, sizes=None,
                       progress=None) -> list:
    """(model, framework, seed, inverse) for each model of MODELS and seed, fitted into FOLDER/fits/seed<k>."""
    from lagbench.replication.studies.robustness import fit_model

    data, out = recording(folder, sizes), []
    for seed in seeds:
        for name in MODELS:
            fitted = fit_model(name, data, Path(folder) / "fits" / f"seed{seed}", framework, int(seed), steps)
            out.append((name, framework, str(seed), fitted.inverse_dynamics))
            if progress:
                progress(f"fit {name} seed {seed}")
    return out


def study(folder, framework: str = "jax", seeds=(0,), steps: int = STEPS, n_refs: int = C.N_REFS,
          duration: float = C.DURATION, sizes=None, progress=None) -> tuple[pd.DataFrame, dict]:
    """The tracking table and traces (`control.tracking_table`) of the four-joint arm's controllers."""
    controllers = C.references_controllers(SYSTEM)
    controllers += fitted_controllers(folder, framework, seeds, steps, sizes, progress)
    return C.tracking_table(controllers, C.FAMILIES, n_refs, duration, system=SYSTEM, progress=progress)


def settings(framework: str = "jax", seeds=(0,), steps: int = STEPS, n_refs: int = C.N_REFS,
             duration: float = C.DURATION, sizes=None) -> dict:
    """What the study ran with (FOLDER/study.json)."""
    from lagbench.replication.studies.robustness import budget

    kp, kd = C.gains(4)
    return {"system": SYSTEM, "framework": framework, "seeds": [int(s) for s in seeds], "steps": int(steps),
            "models": list(MODELS), "budget": budget(steps), "training_data": {**SIZES, **(sizes or {})},
            "train_seed": TRAIN_SEED, "families": list(C.FAMILIES), "n_refs": int(n_refs),
            "ref_duration_s": float(duration), "reference_seed": C.SEED, "control_rate_hz": C.RATE,
            "substeps": C.SUBSTEPS, "kp": kp.tolist(), "kd": kd.tolist()}


def write_study(folder, framework: str = "jax", seeds=(0,), steps: int = STEPS, n_refs: int = C.N_REFS,
                duration: float = C.DURATION, sizes=None, progress=None) -> pd.DataFrame:
    from lagbench.files import results as R

    folder = Path(folder)
    df, traces = study(folder, framework, seeds, steps, n_refs, duration, sizes, progress)
    R.write_json(folder / "study.json", settings(framework, seeds, steps, n_refs, duration, sizes))
    R.write_csv(folder / "tracking.csv", df)
    R.write_npz(folder / "traces.npz", traces)
    return df
