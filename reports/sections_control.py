"""The closed-loop control sections: ``RESULTS/control/`` (the two-link arm with claim 9's models) and
``RESULTS/control_four_joint_arm/`` (the four-joint arm with the models the study fits), each ``tracking.csv``
and ``traces.npz`` from ``lagbench control [--system four_joint_arm]``.

``control_sections(res, out_dir) -> list[Section]``: a section per study folder that holds a tracking table
(`STUDIES`, in order): per reference family, controller and framework the tracking error over seeds
(median [min, max]) and its ratio to PD alone, with a flag for a learned controller no better than PD; and
a figure of the tracking error over time on the first unseen reference. Nothing for a study that has not
run (they are studies beside the claims, not claims).
"""
from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.reports import figures as F
from lagbench.reports.document import Figure, Para, Section, Table
from lagbench.reports.fmt import num
from lagbench.reports.load import Results

FAMILIES = {"test": "unseen shapes (the test family)", "train_x2": "training family, twice as fast"}
GAINS = "gains KP 20, KD 2 sqrt(20)"


@dataclass(frozen=True)
class Study:
    folder: str    # under RESULTS
    title: str
    intro: str
    figure: str    # under the report's folder
    setup: Callable[[Path], str] | None = None   # the run's settings as a sentence, from the study folder


def _four_joint_setup(folder: Path) -> str:
    try:
        s = json.loads((folder / "study.json").read_text())
    except (OSError, ValueError):
        return "The run's settings are not recorded (no study.json)."
    z = s.get("training_data", {})
    return (f"This run: {s.get('framework')}, seeds {', '.join(map(str, s.get('seeds', [])))}, {s.get('steps')} "
            f"optimiser steps of batch 256 for each model alike, on {z.get('n_train')} training-family "
            f"trajectories of {z.get('n_points')} samples (generator seed {s.get('train_seed')}); "
            f"{s.get('n_refs')} references of {s.get('ref_duration_s')} s per family.")


STUDIES = (
    Study("control", "Closed-loop tracking control (study)",
          "The DeLaN paper's experiment: claim 9's inverse models, trained offline on the full data set, give "
          "the feed-forward torque of a computed-torque controller of the simulated two-link arm (500 Hz, "
          f"the SymPy arm as the plant, {GAINS}) on references no model trained on. The "
          "true inverse dynamics is the best a model can do; PD alone is the null controller. A study beside "
          "the claims (`lagbench control`): it decides no verdict.", "figures/control_tracking.png"),
    Study("control_four_joint_arm", "Closed-loop tracking control of the four-joint arm (study)",
          "The same experiment on the SymPy four-joint arm (the first four joints of a Barrett WAM): DeLaN and the "
          "feed-forward net are fitted by the study itself to the arm's training family under one equal budget "
          "(claim 9's model kinds and widths, 64 x 64 softplus, Adam at 1e-3, torque MSE; claim 9's trained "
          f"models are two-link models), then give the feed-forward torque at 500 Hz ({GAINS} on every joint) "
          "on the two-link study's reference families. The true inverse dynamics is the best a model can do; "
          "PD alone is the null controller. A study beside the claims (`lagbench control --system "
          "four_joint_arm`): it decides no verdict.", "figures/control_four_joint_arm_tracking.png",
          _four_joint_setup),
)


def _span(x: pd.Series) -> str:
    x = x.dropna()
    if not len(x):
        return "diverged"
    return num(x.median()) + (f" [{num(x.min())}, {num(x.max())}]" if len(x) > 1 else "")


def _table(df: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for (family, ctl, fw), g in df.groupby(["family", "controller", "framework"], sort=False):
        learned = ctl not in ("exact", "pd")
        worse = learned and (g["ratio_to_pd"].isna() | (g["ratio_to_pd"] >= 1)).any()
        rows.append({"references": FAMILIES.get(family, family), "controller": ctl, "framework": fw,
                     "seeds": str(len(g)) if learned else "-", "tracking MSE (rad²)": _span(g["track_mse"]),
                     "/ PD alone": _span(g["ratio_to_pd"]), "torque effort (N²m²)": _span(g["torque_effort"]),
                     "diverged": str(int(g["n_diverged"].sum())),
                     "flag": "NO BETTER THAN PD in a seed" if worse else "-"})
    return pd.DataFrame(rows)


def _figure(traces: dict, path: Path) -> bool:
    family = "test"
    if f"{family}__q_ref" not in traces:
        return False
    t, ref = traces[f"{family}__t"], traces[f"{family}__q_ref"]
    keys = [k for k in traces if k.startswith(f"{family}__") and k.endswith("__q")]
    if not keys:
        return False
    fig, (ax,) = F.new_figure()
    names = [k.split("__")[1] for k in keys]
    colours = F.model_colours([n for n in names if n not in ("exact", "pd")])
    fws = F.style_index([k.split("__")[2] for k, n in zip(keys, names, strict=True) if n not in ("exact", "pd")])
    for k, name in zip(keys, names, strict=True):
        fw = k.split("__")[2]
        err = np.sqrt(np.sum((traces[k] - ref) ** 2, -1))
        style = {"exact": ("k", "true inverse dynamics"), "pd": ("0.5", "PD alone")}.get(name)
        colour, label = style if style else (colours[name], f"{name} ({fw})")
        ax.plot(t[1:], np.maximum(err[1:], 1e-12), color=colour, ls=F.LINESTYLES[fws.get(fw, 0) % 4], lw=1,
                label=label)
    ax.set_yscale("log")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("|q - q_ref| (rad)")
    ax.set_title("Tracking error on an unseen reference (first seed)", fontsize=10)
    ax.legend(fontsize=7)
    return F.save(fig, path)


def study_section(res: Results, out_dir: Path, study: Study) -> list[Section]:
    """The section of one study folder; nothing when it holds no readable tracking table."""
    folder = res.root / study.folder
    try:
        df = pd.read_csv(folder / "tracking.csv")
    except (OSError, ValueError):
        return []
    s = Section(study.title)
    s.add(Para(study.intro))
    if study.setup:
        s.add(Para(study.setup(folder)))
    s.add(Table("Tracking error per controller (median [min, max] over seeds)", _table(df),
                [f"{study.folder}/tracking.csv"],
                note="Tracking MSE: the mean over references and time of |q - q_ref|²; '/ PD alone' its ratio to the "
                     "PD controller's on the same references."))
    try:
        with np.load(folder / "traces.npz") as z:
            traces = {k: z[k] for k in z.files}
    except (OSError, ValueError):
        traces = {}
    if _figure(traces, out_dir / study.figure):
        s.add(Figure(study.figure, "Closed-loop tracking: the error on the first unseen reference over time, per "
                                   "controller (first seed of each framework).", [f"{study.folder}/traces.npz"],
                     shows="|q - q_ref| (rad) against time t (s)", paper="the DeLaN paper's tracking experiment "
                                                                           "(its tracking-error figure), on our arm"))
    return [s]


def control_sections(res: Results, out_dir: Path) -> list[Section]:
    return [s for study in STUDIES for s in study_section(res, out_dir, study)]
