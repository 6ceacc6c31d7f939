"""The report of a `lagbench fit` or `lagbench evaluate` folder: units of the claims "fit" / "evaluate".

``is_fit_results(res)``: the folder holds such units and nothing else (then ``reports.build`` renders these
sections in place of the claim sections, scorecard and findings, which speak of papers' claims).
``fit_sections(res, out_dir) -> list[Section]``: the data and the models side by side (what each was
trained on and how: task, loss, steps, widths, activation, weight decay, schedule, time), one-step errors
per component (``one_step.csv``), the paragraphs of ``reports.fit_paragraphs`` (the data, what each fit chose
from it and why, the fits no better than the null predictor, the recommended fit), rollout and energy metrics (``result.json``, ``rollouts.csv``), and the
figures: prediction against data (``arrays.npz`` ``<set>_target``/``<set>_pred``), a test trajectory,
energy against truth, DeLaN's terms and the training curves (the drawing functions of ``reports.figures``).
Failed or corrupt units are listed with their reason and left out of every number.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.evaluation.diverged import DIVERGED, SCALED, is_diverged
from lagbench.reports import figures as F
from lagbench.reports import figures_delan as FD
from lagbench.reports.document import Figure, Para, Section, Table
from lagbench.reports.fit_paragraphs import (
    choices_para,
    competence_para,
    data_para,
    recommendation_para,
    unit_name,
)
from lagbench.reports.fmt import cell, count, num
from lagbench.reports.load import Results, protocol_of
from lagbench.reports.tables import problem_units_table

CLAIMS = ("fit", "evaluate")
SRC = "units/{claim}/<framework>/<model>/seed<k>/"
ROLLOUT_METRICS = [("n_diverged", f"rollouts diverged (state error over {DIVERGED:g} x the data's spread, or not finite)"),
                   ("rollout_gmean_err", "state error, geometric mean over time"),
                   ("rollout_final_err", "state error at the end"),
                   ("learned_energy_drift", "learned energy drift (max over time)"),
                   ("energy_err_final", "true energy error at the end"),
                   ("energy_err_max", "true energy error, max over time"),
                   ("mass_matrix_rel_err", "DeLaN M relative error"), ("coriolis_rel_err", "DeLaN c relative error"),
                   ("gravity_rel_err", "DeLaN g relative error"),
                   ("decomposition_scale", "DeLaN: factor to the system's L (accelerations fix L up to one)"),
                   *((f"dissipation_coefficient_{k}", f"friction q{k} in the system's units (--dissipation)")
                     for k in range(4)),
                   ("dissipation_hessian_residual", "--dissipation: learned velocity Hessian against c M, residual"),
                   ("dissipation_ablation", "--dissipation: one-step error without the learned friction / with it"),
                   ("dissipation_bracket_half", "--dissipation: rollout error with the friction halved / as learned"),
                   ("dissipation_bracket_double", "--dissipation: rollout error with the friction doubled / as learned")]


def is_fit_results(res: Results) -> bool:
    return bool(res.units) and all(u.claim in CLAIMS for u in res.units)


def _schedule(protocol) -> str:
    return f"{protocol.schedule.kind}, peak {num(protocol.schedule.lr)}" if protocol else cell(None)


def _loss(p: dict) -> str:
    """The training loss in words: the task's target, positions over windows (`--loss-target trajectory`) or
    q-double-dot through the derivative filter (`--loss-target filtered`)."""
    t, f = p.get("trajectory_loss"), p.get("filter_loss")
    if isinstance(f, dict):
        return (f"{cell(p.get('loss'))} on q-double-dot through the derivative filter (window {f.get('window')}, "
                f"order {f.get('polyorder')})")
    if not isinstance(t, dict):
        return cell(p.get("loss"))
    return (f"{cell(p.get('loss'))} on positions over {t.get('frames')} frames "
            f"({t.get('substeps')} RK4 substeps a frame)")


def _models_table(units) -> pd.DataFrame:
    rows = []
    for u in units:
        p, s, r = u.result.get("protocol") or {}, u.result.get("model_spec") or {}, u.result
        cfg = r.get("eval_config") or {}
        # a fit's --test rows are recorded apart from its own split's
        counts = {**(cfg.get("rows") or {}), **({"test": cfg["test_rows"]} if cfg.get("test_rows") is not None else {})}
        rows.append({"unit": f"{u.claim}: {unit_name(u)}", "task": cell(p.get("task")), "loss": _loss(p),
                     "steps": count(r.get("train_steps")) if u.claim == "fit" else "(the fit's)",
                     "hidden": ",".join(map(str, s.get("hidden") or [])), "activation": cell(s.get("activation")),
                     "weight decay (l2)": num(p.get("l2")), "schedule": _schedule(protocol_of(r)),
                     "rows (train/held-out/test)": "/".join(count(counts.get(k, 0))
                                                            for k in ("train", "heldout", "test")),
                     "final training loss": num(r.get("final_train_loss")), "train time (s)": num(r.get("train_time_s"))})
    return pd.DataFrame(rows)


def _one_step_table(units) -> pd.DataFrame | None:
    frames = []
    for u in units:
        df = u.table("one_step.csv")
        if df is not None and {"set", "quantity", "component", "mae", "rel_mae"} <= set(df.columns):
            frames.append(df.assign(model=unit_name(u), claim=u.claim))
    if not frames:
        return None
    df = pd.concat(frames, ignore_index=True)
    df["value"] = [f"{num(a)} ({num(b)} of null)" for a, b in zip(df["mae"], df["rel_mae"], strict=True)]
    df["row"] = df["claim"] + ": " + df["set"] + " " + df["quantity"] + df["component"].astype(str)
    wide = df.pivot_table(index="row", columns="model", values="value", aggfunc="first", sort=False)
    return wide.reset_index().rename(columns={"row": "rows: quantity"}).fillna("–")


def _rollout_value(u, where: str, key: str) -> str:
    """A rollout metric as the table shows it: an error beyond the data's own scale as "diverged"
    (`evaluation.diverged`), never as a number; the rollouts that diverged as "k of n"."""
    v = u.metric(f"{where}_{key}")
    if v is None:
        return "–"
    if key == "n_diverged":
        of = u.metric(f"{where}_n_trajectories")
        return count(v) + (f" of {count(of)}" if of is not None else "")
    return "diverged" if key in SCALED and is_diverged(v) else num(v)


def _rollout_table(units) -> pd.DataFrame | None:
    rows = []
    for u in units:
        for where in ("heldout", "test"):
            vals = {label: _rollout_value(u, where, k) for k, label in ROLLOUT_METRICS}
            if any(v != "–" for v in vals.values()):
                rows.append({"model": f"{u.claim}: {unit_name(u)}", "rows": where, **vals})
    if not rows:
        return None
    df = pd.DataFrame(rows)
    return df[[c for c in df.columns if c in ("model", "rows") or (df[c] != "–").any()]]


def parity(units, path: Path) -> bool:
    """Prediction against data of each model on its main evaluation rows, one panel per output component."""
    found, names = {}, []
    for u in units:
        arr = u.arrays() or {}
        where = (u.result.get("counters") or {}).get("primary")
        if f"{where}_target" in arr and f"{where}_pred" in arr:
            found[unit_name(u) + ("" if u.claim == "fit" else " [evaluate]")] = (arr[f"{where}_target"], arr[f"{where}_pred"])
            one = u.table("one_step.csv")
            if not names and one is not None and {"set", "quantity", "component"} <= set(one.columns):
                rows = one[one["set"] == where]
                names = [f"{q}{c}" for q, c in zip(rows["quantity"], rows["component"], strict=True)]
    if not found:
        return False
    k = min(next(iter(found.values()))[0].shape[1], 4)
    fig, axes = F.new_figure(ncols=k, width=3.2 * k, height=3.2)
    for j, ax in enumerate(axes):
        lo, hi = np.inf, -np.inf
        for i, (name, (t, p)) in enumerate(found.items()):
            if t.shape[1] <= j:
                continue
            ax.scatter(t[:, j], p[:, j], s=4, alpha=0.5, color=F.colour(i), marker=F.MARKERS[i % 6], label=name)
            lo, hi = min(lo, np.nanmin(t[:, j])), max(hi, np.nanmax(t[:, j]))
        ax.plot([lo, hi], [lo, hi], color="k", lw=0.8, label="prediction = data")
        ax.set_title(names[j] if j < len(names) else f"output {j}", fontsize=9)
        ax.set_xlabel("data")
        ax.set_ylabel("prediction")
    axes[0].legend(fontsize=6)
    return F.save(fig, path)


def fit_sections(res: Results, out_dir: Path) -> list[Section]:
    units = res.usable()
    s = Section("Fitted models")
    s.add(Para(f"{len(res.units)} fitted or evaluated models found, {len(units)} usable (status ok, checksums "
               f"verified). One-step errors are in the quantity trained (q̈, or τ for inverse dynamics) on the "
               f"held-out rows of the training file and on the test file; rollouts start from each test "
               f"trajectory's first state (replication/fit/evaluate.py)."))
    bad = problem_units_table(res)
    if bad is not None:
        s.add(Table("Failed and corrupt units (left out of every number)", bad, ["units/*/*/*/seed*/result.json"]))
    if not units:
        return [s]
    s.add(data_para(units), choices_para(units), competence_para(units), recommendation_para(units))
    s.add(Table("The models side by side", _models_table(units), [SRC.format(claim="*") + "result.json"]))
    out = [s]
    e = Section("Errors", level=2)
    ot = _one_step_table(units)
    if ot is not None:
        e.add(Table("One-step mean absolute error per component (and as a fraction of the null predictor's)", ot,
                    [SRC.format(claim="*") + "one_step.csv"]))
    rt = _rollout_table(units)
    if rt is not None:
        e.add(Table("Rollouts and energy (means over trajectories)", rt, [SRC.format(claim="*") + "result.json"]))
    if e.blocks:
        out.append(e)
    g = Section("Figures", level=2)
    figs = [("parity", parity, "Prediction against data on the test (else held-out) rows", "arrays.npz",
             "predicted against recorded q̈ (or τ)"),
            ("trajectory", F.trajectory, "A test trajectory: data against each model's rollout from its first state",
             "arrays.npz", "coordinates q against time t (s)"),
            ("energy", lambda us, p: F.energy_drift(us, p, "true energy error / mean kinetic energy"),
             "True energy along each rollout against along the data", "timeseries.csv",
             "|true energy error| / mean kinetic energy against time t (s)"),
            ("decomposition", FD.delan_decomposition, "DeLaN's inertia, Coriolis and gravity terms against the "
                                                     "system's", "arrays.npz", "predicted against true torque terms"),
            ("training", F.training_curves, "Training curves", "train_log.csv", "training loss against step")]
    for kind, fn, caption, file, shows in figs:
        rel = f"figures/fit_{kind}.png"
        if fn(units, out_dir / rel):
            g.add(Figure(rel, f"{caption}.", [SRC.format(claim="*") + file], shows=shows))
    if g.blocks:
        out.append(g)
    return out
