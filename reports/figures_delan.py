"""The DeLaN paper's figures recreated from a claim's arrays: the torque decomposition (inertial,
Coriolis/centrifugal, gravity: predicted against true), the torque traces per joint on trajectories
the models never saw, truth against each model, closed-loop tracking of an unseen reference, and the tracking
error over time of models learning online (claim 13)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from lagbench.reports.figures import (
    LINESTYLES,
    MARKERS,
    _groups,
    model_colours,
    new_figure,
    save,
    style_index,
)
from lagbench.reports.load import Unit

DECOMPOSITION = [("M", r"inertia $M(q)$"), ("c", r"Coriolis/centrifugal $c(q, \dot q)$"),
                 ("g", r"gravity $g(q)$"), ("tau", r"torque $\tau$")]


def delan_decomposition(units: list[Unit], path: Path) -> list[str]:
    """Predicted against true, one panel per term the arrays hold (inertia, Coriolis, gravity, torque); returns
    the terms drawn ([] when none)."""
    found = {}
    for key, group in _groups(units).items():
        for u in group:
            arr = u.arrays() or {}
            terms = [(k, name) for k, name in DECOMPOSITION if f"{k}_true" in arr and f"{k}_pred" in arr]
            if terms:
                found[key] = (arr, terms)
                break
    if not found:
        return []
    terms = list(dict.fromkeys(t for _, ts in found.values() for t in ts))
    fig, axes = new_figure(ncols=len(terms), width=3.2 * len(terms), height=3.2)
    colours = model_colours([m for m, _ in found])
    for ax, (k, name) in zip(axes, terms, strict=True):
        lo, hi = np.inf, -np.inf
        for i, ((model, fw), (arr, _)) in enumerate(found.items()):
            if f"{k}_true" not in arr:
                continue
            a = np.asarray(arr[f"{k}_true"], float).ravel()
            b = np.asarray(arr[f"{k}_pred"], float).ravel()
            ax.scatter(a, b, s=4, alpha=0.5, color=colours[model], marker=MARKERS[i % 6], label=f"{model} ({fw})")
            lo, hi = min(lo, np.nanmin(a)), max(hi, np.nanmax(a))
        ax.plot([lo, hi], [lo, hi], color="k", lw=0.8, label="pred = true")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("true (SI units)")
        ax.set_ylabel("predicted (SI units)")
    axes[0].legend(fontsize=7)
    save(fig, path)
    return [re.sub(r"\s*\$.*\$", "", name) for _, name in terms]


def torque_traces(units: list[Unit], path: Path) -> bool:
    """Torque per joint against the sample index of the unseen trajectories: the truth and each model trained
    on the full data set (the data-size sweep's models, `*_n<k>`, left out), first seed of each framework."""
    found = {}
    for (model, fw), group in _groups(units).items():
        if "_n" in model:
            continue
        for u in sorted(group, key=lambda u: str(u.seed)):
            arr = u.arrays() or {}
            if "tau_true" in arr and "tau_pred" in arr:
                found[(model, fw)] = arr
                break
    if not found:
        return False
    ref = np.asarray(next(iter(found.values()))["tau_true"], float)
    ref = ref[:, None] if ref.ndim == 1 else ref
    fig, axes = new_figure(ncols=ref.shape[1], width=3.6 * ref.shape[1], height=3.2)
    models = model_colours([k[0] for k in found])
    fws = style_index([k[1] for k in found])
    for j, ax in enumerate(axes):
        ax.plot(ref[:, j], color="k", lw=2, alpha=0.5, label="truth")
        for (model, fw), arr in found.items():
            pred = np.asarray(arr["tau_pred"], float)
            pred = pred[:, None] if pred.ndim == 1 else pred
            ax.plot(pred[:, j], color=models[model], ls=LINESTYLES[fws[fw] % 4], lw=1, label=f"{model} ({fw})")
        ax.set_xlabel("sample of the unseen trajectories")
        ax.set_ylabel(f"torque joint {j + 1} (N m)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Inverse dynamics on unseen trajectories: torque per joint")
    return save(fig, path)


def tracking(units: list[Unit], path: Path) -> bool:
    """Closed-loop tracking of the first unseen reference (claim 12's `test_t`, `test_q_ref`, `test_q`): each
    joint's reference against the angle each learned controller executed (first seed of each model and
    framework), and the tracking error's norm over time on a log axis."""
    found = {}
    for (model, fw), group in _groups(units).items():
        for u in sorted(group, key=lambda u: str(u.seed)):
            arr = u.arrays() or {}
            if {"test_t", "test_q_ref", "test_q"} <= set(arr):
                found[(model, fw)] = arr
                break
    if not found:
        return False
    first = next(iter(found.values()))
    t, ref = np.asarray(first["test_t"], float), np.asarray(first["test_q_ref"], float)
    dof = ref.shape[-1]
    fig, axes = new_figure(ncols=dof + 1, width=3.4 * (dof + 1), height=3.2)
    models, fws = model_colours([k[0] for k in found]), style_index([k[1] for k in found])
    for ax in axes:
        ax.keep_linear = ("x",)   # time from 0: a linear axis
    for j in range(dof):
        axes[j].plot(t, ref[:, j], color="k", lw=2, alpha=0.5, label="reference")
        axes[j].set_xlabel("time (s)")
        axes[j].set_ylabel(f"joint {j + 1} angle (rad)")
    for (model, fw), arr in found.items():
        q = np.asarray(arr["test_q"], float)
        style = {"color": models[model], "ls": LINESTYLES[fws[fw] % 4], "lw": 1, "label": f"{model} ({fw})"}
        for j in range(dof):
            axes[j].plot(t, q[:, j], **style)
        axes[dof].plot(t[1:], np.linalg.norm(q - ref, axis=-1)[1:], **style)   # both start on the reference
    axes[dof].set_yscale("log")
    axes[dof].set_xlabel("time (s)")
    axes[dof].set_ylabel("|q - q_ref| (rad)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Computed-torque tracking of an unseen reference at 500 Hz")
    return save(fig, path)


def online_learning(units: list[Unit], path: Path) -> bool:
    """Learning online (claim 13's `window_end`, `window_ratio`): each window's tracking MSE over PD alone's in
    the same window, against the seconds learned, one line per unit (colour: model, line style: framework), log
    axis, with PD alone (1) and the unit's threshold (`eval_config` "threshold") dashed."""
    found = [(u, u.arrays() or {}) for u in units]
    found = [(u, a) for u, a in found if {"window_end", "window_ratio"} <= set(a)]
    if not found:
        return False
    fig, axes = new_figure(height=3.4)
    ax = axes[0]
    ax.keep_linear = ("x",)
    models, fws = model_colours([u.model for u, _ in found]), style_index([u.framework for u, _ in found])
    labelled = set()
    for u, arr in sorted(found, key=lambda x: (x[0].model, x[0].framework, str(x[0].seed))):
        t, r = np.asarray(arr["window_end"], float), np.asarray(arr["window_ratio"], float)
        key = (u.model, u.framework)
        ax.plot(t, np.where(np.isfinite(r), r, np.nan), color=models[u.model], ls=LINESTYLES[fws[u.framework] % 4],
                lw=1, alpha=0.8, label=None if key in labelled else f"{u.model} ({u.framework})")
        labelled.add(key)
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="PD alone")
    threshold = ((getattr(found[0][0], "result", None) or {}).get("eval_config") or {}).get("threshold")
    if threshold:
        ax.axhline(float(threshold), color="k", lw=0.8, ls="--", label=f"{float(threshold):g} x PD alone")
    ax.set_yscale("log")
    ax.set_xlabel("time learning online (s)")
    ax.set_ylabel("window tracking MSE / PD alone's")
    ax.legend(fontsize=7)
    fig.suptitle("Tracking error while learning online, 500 Hz (each seed)")
    return save(fig, path)
