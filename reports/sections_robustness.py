"""The robots-that-break-the-assumptions section: ``RESULTS/robustness/`` from ``lagbench robustness``.

``robustness_sections(res, out_dir) -> list[Section]``: per scene (friction, noise, each at its magnitudes)
how much of DeLaN's advantage over the feed-forward net survives, in torque and in tracking error, with and
without DeLaN's dissipation term, the learned friction coefficients and the per-scene recommendation (the
study's own table, `robustness_summary.summary_frame`); the null's and the exact model's tracking for
scale; and the figure of the ratios against the magnitude. Nothing when the study has not run (it is a
study beside the claims, not a claim).
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from lagbench.reports.document import Figure, Para, Section, Table
from lagbench.reports.figures import model_colours
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

FIGURE = "figures/robustness_advantage.png"


def _setup(folder: Path) -> str:
    try:
        s = json.loads((folder / "study.json").read_text())
    except (OSError, ValueError):
        return "The run's settings are not recorded (no robustness/study.json)."
    z = s.get("sizes", {})
    return (f"This run: {s.get('framework')}, seeds {', '.join(map(str, s.get('seeds', [])))}, "
            f"{s.get('steps')} optimiser steps of batch 256 for every model alike; {z.get('n_train')} training "
            f"trajectories of {z.get('n_points')} samples (generator seed {s.get('train_seed')}), torque error on "
            f"{z.get('n_test')} unseen-family trajectories (seed {s.get('test_seed')}), tracking of "
            f"{z.get('n_refs')} unseen references of {z.get('ref_duration')} s. Development draws: no claim "
            f"reads them.")


def _references(df: pd.DataFrame) -> str:
    parts = []
    for name, label in (("zero_torque", "PD alone (the null: no feed-forward torque)"),
                        ("exact", "the scene's true inverse dynamics")):
        x = df.loc[df["model"] == name, "track_mse"].astype(float)
        if len(x):
            parts.append(f"{label} tracks with MSE {num(x.min())} to {num(x.max())} rad²")
    learned = df[~df["model"].isin(("zero_torque", "exact"))]
    diverged = int(learned["n_diverged"].sum()) if "n_diverged" in learned else 0
    return ("For scale, over the scenes: " + "; ".join(parts) + f". References diverged under a learned "
            f"controller: {diverged}.") if parts else ""


def _figure(df: pd.DataFrame, path: Path) -> bool:
    """The study's figure drawn from the table; False (the section goes on without it) where it cannot be."""
    from lagbench.replication.studies.robustness_figure import VARIANTS, advantage_figure

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        advantage_figure(df, path, model_colours(list(VARIANTS)))   # the report's colour per model
    except (KeyError, ValueError, TypeError, OSError):
        return False
    return path.exists()


def robustness_sections(res: Results, out_dir: Path) -> list[Section]:
    from lagbench.replication.studies.robustness_summary import summary_frame

    folder = res.root / "robustness"
    try:
        df = pd.read_csv(folder / "scenes.csv", dtype={"seed": str})
        rec = pd.read_csv(folder / "recommendation.csv")
    except (OSError, ValueError):
        return []
    s = Section("Robots that break the assumptions (study)")
    s.add(Para("The question DeLaN's review asked: how much of DeLaN's advantage over the feed-forward net "
               "(claim 9) survives when the two-link arm has viscous or Coulomb joint friction, noisy recorded "
               "torques, or noisy recorded angles (q̇ and q̈ then estimated by the suite's filter), in torque "
               "error on unseen trajectories and in closed-loop tracking on the scene's own plant; and whether "
               "DeLaN with its learned dissipation term (τ += b q̇, b ≥ 0 per joint) brings it back. A study "
               "beside the claims (`lagbench robustness`, docs/robustness.md): it decides no verdict."))
    s.add(Para(_setup(folder)))
    s.add(Table("DeLaN against the feed-forward net per scene (median over seeds, each seed in brackets)",
                summary_frame(df, rec), ["robustness/scenes.csv", "robustness/recommendation.csv"],
                note="nMSE: torque MSE on the unseen family over the null's (predicting no torque scores 1). "
                     "Ratios: DeLaN's error over the feed-forward net's in the same scene and seed (below 1: "
                     "DeLaN better). b learned: the dissipative DeLaN's friction per joint (N m s/rad). pick: the "
                     "model with the fewest parameters whose median nMSE is within 2x of the best and at most half "
                     "the null's ('none': no model is)."))
    refs = _references(df)
    if refs:
        s.add(Para(refs))
    if _figure(df, out_dir / FIGURE):
        s.add(Figure(FIGURE, "How much of DeLaN's advantage survives: DeLaN's error over the feed-forward net's "
                             "against the violation's magnitude (0: the nominal arm), torque error above, tracking "
                             "error below; at 1 the advantage is gone.", ["robustness/scenes.csv"],
                     shows="DeLaN's error / the feed-forward net's (torque nMSE, tracking MSE) against the magnitude"))
    return [s]

