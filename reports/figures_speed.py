"""Speed, scaling and data-efficiency figures; same contract as :mod:`reports.figures`.

- ``speed_error``: one point per usable unit: x = ``train_samples_per_s`` (else ``train_time_s``),
  y = the claim metric (the label says whether lower or higher is better); colour per model, marker per
  framework; nothing where every cost or every value is 0 (``degenerate`` says why, for the caller to say so).
- ``bench_speed_error``: ``bench/inference.csv``: samples_per_s vs error, one panel per system.
- ``bench_scaling``: ``bench/scaling.csv``: seconds_per_eval vs n per study, formulation and framework.
- ``train_target_curve``: a train-to-target log: held-out L1 vs training samples, one line per protocol
  (a restarts protocol's scouts as points: each is another init), the paper's L1 and the target budget.
- ``data_efficiency``: the claim metric against training-set size N, from model labels ``<model>_n<N>``
  (the runner's convention, e.g. ``delan_n64``); the plain ``<model>`` joins at its protocol ``n_train``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.reports.figures import (
    MARKERS,
    colour,
    log_if_spread,
    model_colours,
    new_figure,
    save,
    style_index,
    ticks_at,
)
from lagbench.reports.load import Unit

SIZE_METRIC = re.compile(r"^(?P<base>.+)_n(?P<n>\d+)$")


def _numeric_rows(df: pd.DataFrame | None, *columns: str) -> pd.DataFrame | None:
    """The rows whose `columns` all parse as numbers, those columns as floats; None if there are none."""
    if df is None:
        return None
    df = df.assign(**{c: pd.to_numeric(df[c], errors="coerce") for c in columns}).dropna(subset=list(columns))
    return None if df.empty else df


def _x(u: Unit) -> tuple[str, float] | None:
    for key, label in (("train_samples_per_s", "training throughput (samples/s)"),
                       ("train_time_s", "training time (s)")):
        v = u.result.get(key)
        if isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v):
            return label, float(v)
    return None


def speed_points(units: list[Unit], metric: str) -> list:
    """[(unit, (x label, x), y)] of the units that record both a cost and the metric, one kind of cost."""
    pts = [(u, _x(u), u.metric(metric)) for u in units]
    pts = [(u, x, y) for u, x, y in pts if x is not None and y is not None]
    return [p for p in pts if p[1][0] == pts[0][1][0]] if pts else []


def degenerate(units: list[Unit], metric: str) -> str:
    """Why a speed-error figure of these units would show nothing ("" when it shows something): every cost or
    every value zero (a model not trained offline records a training time of 0)."""
    pts = speed_points(units, metric)
    if not pts:
        return "no unit records both a training cost and the metric"
    if all(x == 0 for _, (_, x), _ in pts):
        return f"every unit's {pts[0][1][0]} is 0 (no offline training)"
    if all(y == 0 for *_, y in pts):
        return f"every unit's {metric} is 0"
    return ""


def speed_error(units: list[Unit], metric: str, path: Path, higher_better: bool = False) -> bool:
    """One point per unit; nothing (False) where the figure would be degenerate (`degenerate`). The y label
    says which way is better: lower for an error, higher for a share (``higher_better``)."""
    if degenerate(units, metric):
        return False
    pts = speed_points(units, metric)
    label = pts[0][1][0]
    fig, (ax,) = new_figure(height=3.6)
    models = model_colours([u.model for u, _, _ in pts])
    fws = style_index([u.framework for u, _, _ in pts])
    seen = set()
    for u, (_, x), y in pts:
        key = (u.model, u.framework)
        ax.scatter(x, y, color=models[u.model], marker=MARKERS[fws[u.framework] % 6], s=30,
                   label=f"{u.model} ({u.framework})" if key not in seen else None)
        seen.add(key)
    log_if_spread(ax, [x for _, (_, x), _ in pts], axis="x", decades=1.0)
    log_if_spread(ax, [y for *_, y in pts], decades=1.0)
    ax.set_xlabel(label)
    ax.set_ylabel(f"{metric}\n({'higher' if higher_better else 'lower'} is better)")
    ax.legend(fontsize=7)
    return save(fig, path)


def bench_speed_error(df: pd.DataFrame | None, path: Path) -> bool:
    df = _numeric_rows(df, "error", "samples_per_s")
    if df is None:
        return False
    if "mode" in df.columns:  # PyTorch compiled ahead of time gets its own marker: "torch/aoti", "torch/traced"
        aot = df["mode"].astype(str).isin(["aoti", "traced"])
        df = df.assign(framework=df["framework"].astype(str).where(
            ~aot, df["framework"].astype(str) + "/" + df["mode"].astype(str)))
    systems = sorted(df["system"].astype(str).unique())[:6]
    fig, axes = new_figure(ncols=len(systems), width=3.4 * len(systems), height=3.4)
    for ax, system in zip(axes, systems, strict=True):
        g = df[df["system"].astype(str) == system]
        labels = style_index(list(g["model"].astype(str) + "/" + g["formulation"].astype(str)))
        fws = style_index(list(g["framework"].astype(str)))
        for (model, form, fw), h in g.groupby(["model", "formulation", "framework"], sort=True):
            ax.scatter(h["samples_per_s"], h["error"], color=colour(labels[f"{model}/{form}"]),
                       marker=MARKERS[fws[str(fw)] % 6], s=25, label=f"{model}/{form} ({fw})")
        log_if_spread(ax, g["samples_per_s"], axis="x", decades=1.0)
        log_if_spread(ax, g["error"], decades=1.0)
        ax.set_title(system, fontsize=9)
        ax.set_xlabel("inference throughput (samples/s)")
        ax.set_ylabel("error (bench metric)")
        ax.legend(fontsize=6)
    return save(fig, path)


def bench_scaling(df: pd.DataFrame | None, path: Path) -> bool:
    df = _numeric_rows(df, "n", "seconds_per_eval")
    if df is None:
        return False
    studies = sorted(df["study"].astype(str).unique())[:4]
    fig, axes = new_figure(ncols=len(studies), width=3.6 * len(studies), height=3.4)
    for ax, study in zip(axes, studies, strict=True):
        g = df[df["study"].astype(str) == study]
        forms = style_index(list(g["formulation"].astype(str)))
        fws = style_index(list(g["framework"].astype(str)))
        for (form, fw), h in g.groupby(["formulation", "framework"], sort=True):
            h = h.sort_values("n")
            ax.plot(h["n"], h["seconds_per_eval"], color=colour(forms[str(form)]),
                    marker=MARKERS[fws[str(fw)] % 6], label=f"{form} ({fw})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ticks_at(ax, g["n"])
        ax.set_title(study, fontsize=9)
        ax.set_xlabel("size n (degrees of freedom or grid points)")
        ax.set_ylabel("seconds per evaluation (s)")
        ax.legend(fontsize=6)
    return save(fig, path)


def train_target_curve(log: pd.DataFrame | None, path: Path, paper_l1: float = 7.3e-2,
                       budget: float = 3e7) -> bool:
    if log is None:
        return False
    log = log.assign(samples=pd.to_numeric(log["samples"], errors="coerce"),
                     heldout_l1=pd.to_numeric(log["heldout_l1"], errors="coerce"))
    log = log[(log["samples"] > 0) & (log["heldout_l1"] > 0)]
    if log.empty:
        return False
    fig, (ax,) = new_figure(height=3.6)
    names = style_index(list(log["protocol"].astype(str)))
    phase = log["phase"].astype(str) if "phase" in log.columns else pd.Series("train", index=log.index)
    for name, g in log.groupby(log["protocol"].astype(str), sort=False):
        g = g.sort_values("samples")
        scout = phase[g.index].str.startswith("scout").to_numpy()
        if scout.any():  # each scout is its own init: a point each, not a line through them
            ax.scatter(g["samples"][scout], g["heldout_l1"][scout], color=colour(names[name]), marker="x", s=25,
                       label=f"{name}: scouts (one init each)")
        ax.plot(g["samples"][~scout], g["heldout_l1"][~scout], color=colour(names[name]), marker=".", label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axhline(paper_l1, color="k", ls="--", lw=0.8, label=f"paper's {paper_l1:g} (a training loss; held-out 0.069)")
    if log["samples"].max() >= budget / 3:
        ax.axvline(budget, color="grey", ls=":", lw=0.8, label=f"target budget {budget:.0e}")
    ax.set_xlabel("training samples (restarts: every scout counted)")
    ax.set_ylabel("held-out L1 of q''")
    ax.legend(fontsize=7)
    return save(fig, path)


def size_metrics(units: list[Unit], metric: str | None) -> dict[str, list[tuple[str, str, int, float]]]:
    """``{metric: [(model, framework, N, value)]}`` from sized model labels."""
    out: dict[str, list] = {}
    if metric:
        sized = {u.model: SIZE_METRIC.match(u.model) for u in units}
        bases = {m["base"] for m in sized.values() if m}
        for u in units:
            m, value = sized[u.model], u.metric(metric)
            n_train = u.protocol.data.n_train if u.protocol else None
            if value is None:
                continue
            if m:
                out.setdefault(metric, []).append((m["base"], u.framework, int(m["n"]), value))
            elif u.model in bases and isinstance(n_train, int):
                out.setdefault(metric, []).append((u.model, u.framework, n_train, value))
    return out


def data_efficiency(units: list[Unit], path: Path, metric: str | None) -> bool:
    found = size_metrics(units, metric)
    if not found:
        return False
    bases = list(found)[:3]
    fig, axes = new_figure(ncols=len(bases), width=3.6 * len(bases), height=3.4)
    for ax, base in zip(axes, bases, strict=True):
        rows = pd.DataFrame(found[base], columns=["model", "framework", "n", "value"])
        models = model_colours(list(rows["model"]))
        fws = style_index(list(rows["framework"]))
        for (model, fw), g in rows.groupby(["model", "framework"], sort=True):
            s = g.groupby("n")["value"].agg(["mean", "min", "max"])
            ax.errorbar(s.index, s["mean"], yerr=[s["mean"] - s["min"], s["max"] - s["mean"]],
                        color=models[model], marker=MARKERS[fws[fw] % 6], capsize=2,
                        label=f"{model} ({fw})")
        ax.set_xscale("log")
        ticks_at(ax, rows["n"])
        if (rows["value"] > 0).all():   # log-log, as DeLaN's and every data-efficiency curve is read
            ax.set_yscale("log")
        ax.set_xlabel("training samples N")
        ax.set_ylabel(base.replace("_", " "))
        ax.legend(fontsize=7)
    return save(fig, path)
