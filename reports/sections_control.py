"""The closed-loop control section: ``RESULTS/control/tracking.csv`` and ``traces.npz`` from ``lagbench control``.

``control_sections(res, out_dir) -> list[Section]``: per reference family, controller and framework the
tracking error over seeds (median [min, max]) and its ratio to PD alone, with a flag for a learned
controller no better than PD; and a figure of the tracking error over time on the first unseen reference.
Nothing when the study has not run (it is a study beside the claims, not a claim).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from reports import figures as F
from reports.document import Figure, Para, Section, Table
from reports.fmt import num
from reports.load import Results

FAMILIES = {"test": "unseen shapes (the test family)", "train_x2": "training family, twice as fast"}


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


def control_sections(res: Results, out_dir: Path) -> list[Section]:
    folder = res.root / "control"
    try:
        df = pd.read_csv(folder / "tracking.csv")
    except (OSError, ValueError):
        return []
    s = Section("Closed-loop tracking control (study)")
    s.add(Para("The DeLaN paper's experiment: claim 9's inverse models, trained offline on the full data set, give "
               "the feed-forward torque of a computed-torque controller of the simulated two-link arm (500 Hz, "
               "the SymPy arm as the plant, gains KP 20, KD 2 sqrt(20)) on references no model trained on. The "
               "true inverse dynamics is the best a model can do; PD alone is the null controller. A study beside "
               "the claims (`lagbench control`): it decides no verdict."))
    s.add(Table("Tracking error per controller (median [min, max] over seeds)", _table(df), ["control/tracking.csv"],
                note="Tracking MSE: the mean over references and time of |q - q_ref|²; '/ PD alone' its ratio to the "
                     "PD controller's on the same references."))
    try:
        with np.load(folder / "traces.npz") as z:
            traces = {k: z[k] for k in z.files}
    except (OSError, ValueError):
        traces = {}
    rel = "figures/control_tracking.png"
    if _figure(traces, out_dir / rel):
        s.add(Figure(rel, "Closed-loop tracking: the error on the first unseen reference over time, per controller "
                          "(first seed of each framework).", ["control/traces.npz"]))
    return [s]
