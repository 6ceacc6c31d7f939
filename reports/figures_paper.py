"""Figures of the LNN paper recreated from a claim's files, beyond the double pendulum's (`reports.figures`):
- ``model_panels``: one panel per paper model, the velocity over time from a few initial states, truth
  against the model (``arrays.npz`` keys t, qdot_true, qdot_pred (n, T, d)): the relativistic particle's Fig. 3.
- ``wave_energy``: the wave's total energy over time, truth against each model, and the model's error
  relative to the truth's energy on a log axis (``timeseries.csv`` quantities energy_true, energy_pred):
  the energy statement of Fig. 4. Diverged seeds are counted, not drawn.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from lagbench.reports.figures import (
    DIVERGED,
    LINESTYLES,
    _first_with,
    _groups,
    model_colours,
    new_figure,
    save,
    style_index,
)
from lagbench.reports.load import Unit


def model_panels(units: list[Unit], path: Path, models: list[str]) -> list[str]:
    """Panel per model of `models` (in that order; JAX's where both frameworks ran): the velocity of each
    rollout, truth solid and grey, the model dashed in its colour (first seed). Returns the models drawn
    ([] when none has the arrays)."""
    found, fws = {}, {}
    for (m, fw), arr in sorted(_first_with(units, ("t", "qdot_true", "qdot_pred")).items(),
                               key=lambda kv: kv[0][1] != "jax"):   # JAX's where both frameworks ran
        if m not in found:
            found[m], fws[m] = arr, fw
    shown = [m for m in models if m in found]
    if not shown:
        return []
    fig, axes = new_figure(ncols=len(shown), width=3.3 * len(shown) + 0.6, height=3.2, gap=0.75)
    colours = model_colours(shown)
    for ax, m in zip(axes, shown, strict=True):
        arr = found[m]
        t = np.asarray(arr["t"], float)
        true, pred = np.asarray(arr["qdot_true"], float), np.asarray(arr["qdot_pred"], float)
        for i in range(true.shape[0]):
            ax.plot(t, true[i, :, 0], color="k", lw=2, alpha=0.35, label="truth" if i == 0 else None)
            ax.plot(t, pred[i, :, 0], color=colours[m], ls="--", lw=1.2, label="model" if i == 0 else None)
        diverged = int(np.sum(~np.all(np.isfinite(pred), axis=(1, 2))))
        ax.set_title(f"{m} ({fws[m]})" + (f", {diverged} diverged" if diverged else ""), fontsize=9)
        ax.set_xlabel("time t (s)")
        ax.set_ylabel("velocity q̇ (units of c)")
    axes[0].legend(fontsize=7)
    save(fig, path)
    return shown


def _energies(u: Unit):
    ts = u.table("timeseries.csv")
    if ts is None or not {"t", "quantity", "value"} <= set(ts.columns):
        return None
    get = {q: g.groupby("t")["value"].mean() for q, g in ts.groupby("quantity")}
    if "energy_true" not in get or "energy_pred" not in get:
        return None
    true, pred = get["energy_true"], get["energy_pred"].reindex(get["energy_true"].index)
    return true.index.to_numpy(float), true.to_numpy(float), pred.to_numpy(float)


def wave_energy(units: list[Unit], path: Path) -> bool:
    """Left: total energy over time, the truth (first unit's) and each model and framework (median over seeds,
    band: seed range). Right: |E_model - E_true| / E_true(0) on a log axis. A seed whose relative error ever
    exceeds `DIVERGED` (or is not finite) has diverged: it is counted in the legend, not drawn."""
    curves, diverged = {}, {}
    for key, group in _groups(units).items():
        got = [e for e in (_energies(u) for u in group) if e is not None]
        kept = [e for e in got if np.all(np.abs(e[2] - e[1]) <= DIVERGED * abs(e[1][0]))]
        if kept:
            curves[key], diverged[key] = kept, len(got) - len(kept)
    if not curves:
        return False
    fig, (ax, ax_err) = new_figure(ncols=2, width=10, height=3.4, gap=1.1)
    colours = model_colours([m for m, _ in curves])
    fws = style_index([fw for _, fw in curves])
    t0, e_true, _ = next(iter(curves.values()))[0]
    ax.plot(t0, e_true, color="k", lw=2, alpha=0.4, label="truth")
    for (m, fw), got in curves.items():
        t = got[0][0]
        pred = np.vstack([np.interp(t, g[0], g[2]) for g in got])
        err = np.abs(pred - np.vstack([np.interp(t, g[0], g[1]) for g in got])) / np.array([[abs(g[1][0])] for g in got])
        kw = {"color": colours[m], "ls": LINESTYLES[fws[fw] % 4]}
        n_div = diverged[(m, fw)]
        label = f"{m} ({fw}, {len(got)} seed{'s' * (len(got) > 1)}" + (f"; {n_div} more diverged" if n_div else "") + ")"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ax.plot(t, np.nanmedian(pred, 0), label=label, **kw)
            ax_err.plot(t[1:], np.nanmedian(err, 0)[1:], label=label, **kw)
            if len(got) > 1:
                ax.fill_between(t, np.nanmin(pred, 0), np.nanmax(pred, 0), color=kw["color"], alpha=0.15, lw=0)
                ax_err.fill_between(t[1:], np.nanmin(err, 0)[1:], np.nanmax(err, 0)[1:], color=kw["color"],
                                    alpha=0.15, lw=0)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("total energy E (–)")
    ax.set_title("Energy integrated over the grid", fontsize=10)
    ax_err.set_yscale("log")
    ax_err.set_xlabel("time t (s)")
    ax_err.set_ylabel("|E_model − E_true| / E_true(0) (–)")
    ax_err.set_title("Energy error against truth", fontsize=10)
    ax.legend(fontsize=7)
    return save(fig, path)
