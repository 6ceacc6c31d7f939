"""How much of DeLaN's advantage over a feed-forward net survives arms that break its assumptions.

For every scene of `robustness_scenes.SCENES` (nominal; viscous and Coulomb joint friction; noise on the
recorded torques; noise on the recorded q with qdot and qddot estimated by the suite's filter) and every
seed: a recording of the training family ("train", `SIZES`: 16 trajectories x 200 samples over 4 s, 50 Hz,
generator seed `TRAIN_SEED`) is written as a `lagbench fit` trajectory file and each model of
`MODELS` is fitted to it by `replication.fit.task.fit` under one equal budget (`budget`): `steps`
optimiser steps (default `STEPS`) of batch 256, widths `HIDDEN`, softplus, Adam at a constant 1e-3, torque
MSE with weight decay 1e-5 (claim 9's protocol, shorter), all rows trained on, the seed the
initialisation's and the noise's. Models: "delan"; "delan_dissipation", DeLaN with its learned viscous
friction tau += b qdot, b >= 0 per joint (`ModelSpec.dissipation`); "ff", the feed-forward net of
(q, qdot, qddot). Two references are scored alike: "zero_torque", the null model (it predicts no torque:
PD alone in the loop), and "exact", the scene's true inverse dynamics (the best any model can do).

Scores, per model: `torque_nmse`, the torque MSE on the unseen family ("test", 8 trajectories x 200 samples,
seed `TEST_SEED`, exact states) against the scene's true torques, divided by the null's (so the null
scores 1: the column is also the ratio to the null); `track_mse`, closed-loop computed-torque tracking
(`control.track` on the scene's plant: its controller, gains and divergence rule) of 4
references of the unseen family (`control.references`, seed 2000) of 2 s each, MSE of q summed
over joints (`control.scores`), with `n_diverged`; ratios to ff (same scene, framework, seed) and to the
null's tracking; `params`, the model's parameter count; `b0`, `b1`, the learned friction coefficients of
"delan_dissipation" (N m s/rad; NaN elsewhere).

`recommend(df)`: per scene, magnitude and framework, the cheapest learned model (fewest parameters) whose
median torque_nmse over seeds is within `WITHIN` (2x) of the best learned model's and clearly better than
the null (at most `NULL_FRACTION` of its error, the suite's "did it learn" line); "none" when no model is.
`write_study(out, ...)` writes OUT/scenes.csv, OUT/recommendation.csv, OUT/summary.md, OUT/advantage.png
(`robustness_figure`), OUT/study.json (what it ran with), the recordings in OUT/data/ and the fits in
OUT/fits/<scene>/seed<k>/ (a rerun reuses every fit of the same data and options).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.studies.robustness_scenes import SCENES, UNITS, Plant, scene_data, write_recording

MODELS = {"delan": {"model": "delan"}, "delan_dissipation": {"model": "delan", "dissipation": True},
          "ff": {"model": "baseline"}}
UNIT_LABEL = {"delan": "delan", "delan_dissipation": "delan_dissipative", "ff": "baseline"}   # fit's folders
STEPS = 3000
HIDDEN = (64, 64)
SIZES = {"n_train": 16, "n_test": 8, "n_points": 200, "n_refs": 4, "ref_duration": 2.0}
TRAIN_SEED, TEST_SEED = 2001, 2002   # development draws: no claim reads them (claim 12 tracks 3000 on the test split)
WITHIN, NULL_FRACTION = 2.0, 0.5
NULL = "zero_torque"   # the null model's name (not "null", which pandas reads as a missing value)
COLUMNS = ("scene", "kind", "magnitude", "unit", "model", "framework", "seed", "params", "torque_nmse", "track_mse",
           "n_diverged", "torque_ratio_to_ff", "track_ratio_to_ff", "track_ratio_to_null", "b0", "b1")
REC_COLUMNS = ("scene", "kind", "magnitude", "framework", "recommended", "params", "torque_nmse", "best_model",
               "best_torque_nmse", "candidates")


def budget(steps: int) -> dict:
    """The fit options every model gets alike (the rest are claim 9's, the same for DeLaN and ff)."""
    return {"steps": int(steps), "hidden": HIDDEN, "batch": 256, "lr": 1e-3, "schedule": "constant",
            "weight_decay": 1e-5, "loss": "mse", "activation": "softplus", "split": "none", "input_scale": None,
            "restarts": 0, "guard_clip": 0.0, "guard_skip": 0.0}


def score(inverse, test: dict, refs: dict, plant) -> dict:
    """torque_nmse on the test set and the tracking scores; `inverse` None is the null (zero torque)."""
    q, v, a, tau = (test[k].reshape(-1, test[k].shape[-1]) for k in ("q", "qdot", "qddot", "tau"))
    pred = np.zeros_like(tau) if inverse is None else np.asarray(inverse(q, v, a), np.float64)
    from lagbench.replication.studies.control import scores, track

    tracked = scores(track(inverse, refs, plant=plant), refs)
    return {"torque_nmse": float(np.mean((pred - tau) ** 2) / np.mean(tau ** 2)),
            "track_mse": tracked.get("track_mse", np.nan), "n_diverged": tracked["n_diverged"]}


def fit_model(name: str, data, folder, framework: str, seed: int, steps: int):
    """Fit model `name` of MODELS to the recording `data` into `folder`; the loaded `Fitted`."""
    from lagbench.files import results as R
    from lagbench.replication.fit.load import load_fitted
    from lagbench.replication.fit.task import fit
    from lagbench.replication.fit.trajectories import WINDOW

    # the study's fixed Savitzky-Golay window (docs/robustness.md), not fit's data-chosen default
    fit(str(data), out=str(folder), framework=framework, seed=int(seed), window=WINDOW, **budget(steps), **MODELS[name])
    return load_fitted(R.unit_dir(folder, "fit", framework, UNIT_LABEL[name], seed))


def _learned_row(name, fitted) -> dict:
    params = {k: np.asarray(p) for k, p in fitted.params.items()}
    b = np.log1p(np.exp(params["dissipation.raw"].astype(np.float64))) if "dissipation.raw" in params else [np.nan] * 2
    return {"params": int(sum(p.size for p in params.values())), "b0": float(b[0]), "b1": float(b[1])}


def study(out, framework: str = "jax", seeds=(0,), steps: int = STEPS, scenes=None, sizes=None,
          progress=None, jobs: int = 1) -> pd.DataFrame:
    """The scenes table (COLUMNS), fitting into OUT/data and OUT/fits; `scenes` default SCENES, `sizes`
    (the data and references) SIZES, both read when called; `progress(what)` after every model scored.
    `jobs` > 1: the scenes in that many worker processes (spawned, one thread each, as `lagbench run`'s
    workers), each scene's rows as one scene alone gives them; progress then comes a scene at a time."""
    out, scenes, z = Path(out), SCENES if scenes is None else scenes, {**SIZES, **(sizes or {})}
    (out / "data").mkdir(parents=True, exist_ok=True)
    args = [(scene, out, framework, tuple(seeds), steps, z) for scene in scenes]
    rows = []
    if int(jobs) <= 1:
        for a in args:
            rows += scene_rows(*a, progress=progress)
    else:
        for scene_done in _in_workers(args, int(jobs)):
            rows += scene_done
            for r in scene_done if progress else ():
                progress(f"{r['scene']} {r['model']}" + (f" seed {r['seed']}" if r["seed"] != "-" else ""))
    return with_ratios(pd.DataFrame(rows))


def scene_rows(scene, out: Path, framework: str, seeds, steps: int, z: dict, progress=None) -> list[dict]:
    """One scene's rows: the null and the exact model, then every model of MODELS fitted for every seed."""
    from lagbench.replication.studies.control import references

    refs = references("test", z["n_refs"], z["ref_duration"])
    plant, rows = Plant(scene), []
    test = scene_data(scene, "test", z["n_test"], z["n_points"], TEST_SEED)
    base = {"scene": scene.id, "kind": scene.kind, "magnitude": scene.magnitude, "unit": UNITS[scene.kind]}
    for name, inverse in ((NULL, None), ("exact", plant.inverse_dynamics)):
        rows.append({**base, "model": name, "framework": "numpy", "seed": "-", "params": 0,
                     **score(inverse, test, refs, plant)})
        if progress:
            progress(f"{scene.id} {name}")
    for seed in seeds:
        data = out / "data" / f"{scene.id}-seed{seed}.npz"
        write_recording(scene_data(scene, "train", z["n_train"], z["n_points"], TRAIN_SEED, noise_seed=seed), data, scene)
        for name in MODELS:
            fitted = fit_model(name, data, out / "fits" / scene.id / f"seed{seed}", framework, seed, steps)
            rows.append({**base, "model": name, "framework": framework, "seed": str(seed),
                         **_learned_row(name, fitted), **score(fitted.inverse_dynamics, test, refs, plant)})
            if progress:
                progress(f"{scene.id} {name} seed {seed}")
    return rows


def _scene_task(a):
    return scene_rows(*a)


def _in_workers(args, jobs: int):
    """Each scene's rows, in the scenes' order, from `jobs` spawned processes of one thread each."""
    import os
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    from lagbench.replication.run.environment import one_thread_children, worker_start

    with one_thread_children(), ProcessPoolExecutor(min(jobs, len(args)), mp_context=get_context("spawn"),
                                                    initializer=worker_start, initargs=(os.getpid(),)) as pool:
        yield from pool.map(_scene_task, args)


def with_ratios(df: pd.DataFrame) -> pd.DataFrame:
    """The ratio columns: to ff of the same scene, framework and seed, and to the null's tracking."""
    key = ["scene", "framework", "seed"]
    ff = df[df["model"] == "ff"].set_index(key)[["torque_nmse", "track_mse"]]
    idx = pd.MultiIndex.from_frame(df[key])
    df = df.copy()
    for col in ("torque", "track"):
        df[f"{col}_ratio_to_ff"] = df[f"{col}_{'nmse' if col == 'torque' else 'mse'}"].to_numpy() / \
            ff[f"{col}_{'nmse' if col == 'torque' else 'mse'}"].reindex(idx).to_numpy()
    null = df[df["model"] == NULL].set_index("scene")["track_mse"]
    df["track_ratio_to_null"] = df["track_mse"] / df["scene"].map(null)
    for col in COLUMNS:
        if col not in df:
            df[col] = np.nan
    return df[list(COLUMNS)]


def recommend(df: pd.DataFrame) -> pd.DataFrame:
    """Per scene and framework, the cheapest learned model within WITHIN of the best torque error (see the
    module docstring); the null and the exact model are references, never candidates."""
    learned = df[~df["model"].isin([NULL, "exact"])]
    rows = []
    for (scene, fw), g in learned.groupby(["scene", "framework"], sort=False):
        m = g.groupby("model", sort=False).agg(torque_nmse=("torque_nmse", "median"), params=("params", "max"))
        best = m["torque_nmse"].idxmin()
        ok = m[(m["torque_nmse"] <= WITHIN * m.loc[best, "torque_nmse"]) & (m["torque_nmse"] <= NULL_FRACTION)]
        pick = ok.sort_values(["params", "torque_nmse"]).index[0] if len(ok) else "none"
        rows.append({"scene": scene, "kind": g["kind"].iloc[0], "magnitude": g["magnitude"].iloc[0], "framework": fw,
                     "recommended": pick, "params": int(ok.loc[pick, "params"]) if len(ok) else 0,
                     "torque_nmse": float(ok.loc[pick, "torque_nmse"]) if len(ok) else np.nan,
                     "best_model": best, "best_torque_nmse": float(m.loc[best, "torque_nmse"]),
                     "candidates": ";".join(ok.index)})
    return pd.DataFrame(rows, columns=list(REC_COLUMNS))


def write_study(out, **kw) -> tuple[pd.DataFrame, pd.DataFrame]:
    """study(), then OUT/scenes.csv, OUT/recommendation.csv, OUT/summary.md, OUT/advantage.png and
    OUT/study.json (the framework, seeds, steps, fit options, sizes and data seeds it ran with)."""
    from lagbench.files import results as R
    from lagbench.replication.studies.robustness_figure import advantage_figure
    from lagbench.replication.studies.robustness_summary import summary_markdown

    out = Path(out)
    df = study(out, **kw)
    rec = recommend(df)
    R.write_json(out / "study.json", {"framework": kw.get("framework", "jax"), "seeds": [int(x) for x in
                 kw.get("seeds", (0,))], "steps": int(kw.get("steps", STEPS)), "budget": budget(kw.get("steps", STEPS)),
                 "sizes": {**SIZES, **(kw.get("sizes") or {})}, "train_seed": TRAIN_SEED, "test_seed": TEST_SEED})
    R.write_csv(out / "scenes.csv", df)
    R.write_csv(out / "recommendation.csv", rec)
    R.atomic_write_bytes(out / "summary.md", summary_markdown(df, rec).encode())
    advantage_figure(df, out / "advantage.png")
    return df, rec
