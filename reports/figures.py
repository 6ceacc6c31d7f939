"""Per-claim figures, one function each; matplotlib without pyplot (no global state, Agg via savefig).

Every function takes the claim's usable units and a PNG path, writes the figure and returns True, or
returns False (writing nothing) when the units lack the data it needs. Inputs:
- ``energy_drift``: ``timeseries.csv`` rows with ``quantity == "energy_err"`` (traj, t, value): |error| on a
  log axis, medians over rollouts and seeds, diverged rollouts counted apart.
- ``trajectory``: ``arrays.npz`` keys ``t`` (T,), ``q_true`` and ``q_pred`` ((T, n) or (n_traj, T, n)).
- ``wave_spacetime``: ``arrays.npz`` keys ``x`` (n,), ``t`` (T,), ``field_true``/``field_pred`` (T, n).
- ``delan_decomposition`` and ``torque_traces`` are in :mod:`reports.figures_delan`.
- ``training_curves``: ``train_log.csv`` (step, loss) averaged over seeds per model and framework.
"""

from __future__ import annotations

import io
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from lagbench.replication.evaluation.diverged import DIVERGED
from lagbench.reports.load import Unit
from lagbench.reports.output import write

DPI = 130
LINESTYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D", "v", "P"]


def new_figure(ncols: int = 1, nrows: int = 1, width: float = 6.4, height: float = 3.4, gap: float = 0.95,
               right: float = 0.2):
    """Fixed margins, ``gap`` between panels and ``right`` margin (inches) instead of constrained layout,
    which doubles the drawing time."""
    fig = Figure(figsize=(width, height * nrows))
    axes = fig.subplots(nrows, ncols, squeeze=False)
    panel = (width - 1.05 - right - gap * (ncols - 1)) / ncols
    fig.subplots_adjust(left=1.05 / width, right=1 - right / width, bottom=0.55 / height, top=1 - 0.4 / height,
                        wspace=gap / panel, hspace=0.35)
    return fig, list(axes.ravel())


LINEAR_DECADES = 3.0   # a linear axis over positive values spanning more decades than this is drawn on a log axis


def _values(ax, axis: str) -> np.ndarray:
    """The finite values an axes plots along ``axis`` (lines and scatter points)."""
    k = 0 if axis == "x" else 1
    parts = [np.asarray(ln.get_xdata() if k == 0 else ln.get_ydata(), dtype=float).ravel() for ln in ax.get_lines()]
    parts += [np.asarray(c.get_offsets(), dtype=float).reshape(-1, 2)[:, k] for c in ax.collections
              if hasattr(c, "get_offsets") and len(c.get_offsets())]
    v = np.concatenate(parts) if parts else np.zeros(0)
    return v[np.isfinite(v)]


def linear_span(ax, axis: str = "y") -> float:
    """Decades spanned by the positive values on a linear axis (0 for a log axis or values of both signs)."""
    if (ax.get_yscale() if axis == "y" else ax.get_xscale()) != "linear" or ax.images:
        return 0.0
    v = _values(ax, axis)
    v = v[v != 0]
    return float(np.log10(v.max() / v.min())) if v.size and (v > 0).all() else 0.0


def save(fig: Figure, path: Path) -> bool:
    """Render to memory, then replace ``path`` atomically (never writing through a symlink there). A linear
    axis whose positive values span more than `LINEAR_DECADES` becomes a log axis first (one outlier must not
    flatten every other curve), unless the figure marks it linear (`ax.keep_linear`, e.g. a time axis). The
    PNG is cut to what is drawn (``bbox_inches="tight"``), so no title, label or legend is clipped."""
    for ax in fig.axes:
        for axis in ("x", "y"):
            if axis not in getattr(ax, "keep_linear", ()) and linear_span(ax, axis) > LINEAR_DECADES:
                (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight", pad_inches=0.06)
    write(path, buf.getvalue())
    return True


# colour-blind safe: Okabe and Ito's colours less black (the truth is drawn in black or grey) and Tol's muted
# wine, olive, indigo and teal; the first six are the model kinds', the rest (yellow last: faint on white)
# a sweep's further arms'
PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#882255", "#999933", "#332288",
           "#44AA99", "#F0E442"]


def colour(i: int) -> str:
    return PALETTE[i % len(PALETTE)]


def style_index(values: list[str]) -> dict[str, int]:
    return {v: i for i, v in enumerate(dict.fromkeys(values))}


# one colour per model kind across the report (a label's kind is its part before the first "_"): the DeLaN
# paper's pair (DeLaN, the feed-forward net) and the LNN paper's (LNN, baseline) in contrasting hues
KIND_COLOURS = {"baseline": PALETTE[0], "lnn": PALETTE[1], "hnn": PALETTE[2], "delan": PALETTE[3],
                "lgn": PALETTE[4], "ff": PALETTE[5]}


def model_colours(labels: list[str]) -> dict[str, str]:
    """A colour per model: its kind's (`KIND_COLOURS`) when the figure's models are of different kinds, so a
    kind keeps its colour from figure to figure; where two share a kind (an ablation, a data sweep), the
    kind's own name, else its first label, keeps the kind's colour and the other arms take colours no kind
    owns, then those of kinds the figure does not show, so that no arm wears another kind's colour."""
    labels = list(dict.fromkeys(labels))
    kinds = {x: x.split("_", 1)[0] for x in labels}
    if len(set(kinds.values())) == len(labels) and all(k in KIND_COLOURS for k in kinds.values()):
        return {x: KIND_COLOURS[k] for x, k in kinds.items()}
    out = {x: KIND_COLOURS[x] for x in labels if x in KIND_COLOURS}
    for x, k in kinds.items():
        if x not in out and k in KIND_COLOURS and KIND_COLOURS[k] not in out.values():
            out[x] = KIND_COLOURS[k]
    shown = {KIND_COLOURS[k] for k in kinds.values() if k in KIND_COLOURS}
    spare = [c for c in PALETTE if c not in KIND_COLOURS.values()] + [c for c in KIND_COLOURS.values() if c not in shown]
    rest = iter(spare * (len(labels) // len(spare) + 1))
    return {x: out[x] if x in out else next(rest) for x in labels}


def log_if_spread(ax, values, axis: str = "y", decades: float = 1.5) -> None:
    arr = np.asarray(values, dtype=float)
    arr = arr[np.isfinite(arr)]
    if arr.size and (arr > 0).all() and np.log10(arr.max() / arr.min()) >= decades:
        (ax.set_yscale if axis == "y" else ax.set_xscale)("log")


def ticks_at(ax, values, axis: str = "x") -> None:
    """Label a log axis at the given values (plain numbers) instead of 2×10⁰-style minor labels."""
    vals = sorted({float(v) for v in values if np.isfinite(v) and v > 0})
    if 0 < len(vals) <= 8:
        setter = ax.set_xticks if axis == "x" else ax.set_yticks
        setter(vals, [f"{v:g}" for v in vals])
        setter([], minor=True)


def _groups(units: list[Unit]) -> dict[tuple[str, str], list[Unit]]:
    out: dict[tuple[str, str], list[Unit]] = {}
    for u in units:
        out.setdefault((u.model, u.framework), []).append(u)
    return out


# |energy error| over its scale above DIVERGED (or non-finite) at any time: a diverged rollout, left out of the curves


def _energy_per_seed(u: Unit):
    """(t, median over the seed's rollouts of |energy error| per time, rollouts, diverged), or None."""
    ts = u.table("timeseries.csv")
    if ts is None or not {"t", "quantity", "value", "traj"} <= set(ts.columns):
        return None
    e = ts[ts["quantity"] == "energy_err"]
    if "set" in e.columns and len(e):   # a fit's: its test file's rollouts where it has them
        e = e[e["set"] == ("test" if (e["set"] == "test").any() else e["set"].iloc[0])]
    if not len(e):
        return None
    per = {k: g.set_index("t")["value"].abs() for k, g in e.groupby("traj")}
    bad = [k for k, v in per.items() if not (np.isfinite(v).all() and (v <= DIVERGED).all())]
    kept = pd.DataFrame({k: v for k, v in per.items() if k not in bad}).sort_index()
    t = np.unique(e["t"].to_numpy(float))
    curve = kept.reindex(t).median(axis=1).to_numpy(float) if kept.shape[1] else np.full(t.size, np.nan)
    return t, curve, len(per), len(bad)


def energy_drift(units: list[Unit], path: Path, scale_label: str = "relative energy error",
                 published: dict | None = None) -> bool:
    """|energy error| against time on a log axis, as the LNN paper's Fig. 2(b): per model and framework the median
    over seeds of each seed's median over its rollouts, the band from the lowest to the highest seed; a rollout
    whose error ever exceeds `DIVERGED` is left out of the curves and counted in the legend. `published`:
    {model: (value, its conditions)}, each a dotted line in the model's colour."""
    curves = {}
    for key, group in _groups(units).items():
        seeds = [c for c in (_energy_per_seed(u) for u in group) if c is not None]
        if seeds:
            curves[key] = seeds
    if not curves:
        return False
    fig, (ax,) = new_figure()
    models = model_colours([k[0] for k in curves])
    fws = style_index([k[1] for k in curves])
    for (model, fw), seeds in curves.items():
        t = seeds[0][0]
        stack = np.vstack([np.interp(t, c[0], c[1]) if c[0].size > 1 else c[1] for c in seeds])
        n, bad = sum(c[2] for c in seeds), sum(c[3] for c in seeds)
        kw = {"color": models[model], "ls": LINESTYLES[fws[fw] % 4]}
        label = f"{model} ({fw}, {len(seeds)} seed{'s' * (len(seeds) > 1)}" + (f"; {bad} of {n} rollouts diverged"
                                                                              if bad else "") + ")"
        after = slice(1, None)   # the start is exact by construction: no point on a log axis
        with warnings.catch_warnings():   # a time at which every rollout of every seed diverged: NaN, no point
            warnings.simplefilter("ignore", RuntimeWarning)
            mid, lo, hi = np.nanmedian(stack, axis=0), np.nanmin(stack, 0), np.nanmax(stack, 0)
        ax.plot(t[after], mid[after], label=label, **kw)
        if len(seeds) > 1:
            ax.fill_between(t[after], lo[after], hi[after], color=kw["color"], alpha=0.15, lw=0)
    for model, (value, where) in (published or {}).items():
        if model in models and value > 0:
            ax.axhline(value, color=models[model], ls=":", lw=1.2, label=f"published {model}: {value:.2g} ({where})")
    ax.set_yscale("log")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(f"|{scale_label}| (–)")
    ax.set_title("Energy error against truth (median over rollouts and seeds)", fontsize=10)
    ax.legend(fontsize=7)
    return save(fig, path)


def _first_with(units: list[Unit], keys: tuple[str, ...]) -> dict[tuple[str, str], dict]:
    """First unit (lowest seed) per (model, framework) whose arrays hold all ``keys``."""
    out = {}
    for key, group in _groups(units).items():
        for u in group:
            arr = u.arrays()
            if arr is not None and all(k in arr for k in keys):
                out[key] = arr
                break
    return out


def trajectory(units: list[Unit], path: Path) -> bool:
    found = _first_with(units, ("t", "q_true", "q_pred"))
    if not found:
        return False

    def first_traj(q):
        q = np.asarray(q, dtype=float)
        return q[0] if q.ndim == 3 else (q[:, None] if q.ndim == 1 else q)

    ref = next(iter(found.values()))
    dof = min(first_traj(ref["q_true"]).shape[1], 4)
    fig, axes = new_figure(ncols=dof, width=3.3 * dof)
    models = model_colours([k[0] for k in found])
    fws = style_index([k[1] for k in found])
    for j, ax in enumerate(axes):
        t = np.asarray(ref["t"], dtype=float)
        ax.plot(t, first_traj(ref["q_true"])[: len(t), j], color="k", lw=2, alpha=0.5, label="truth")
        for (model, fw), arr in found.items():
            tt = np.asarray(arr["t"], dtype=float)
            qp = first_traj(arr["q_pred"])
            ax.plot(tt[: len(qp)], qp[: len(tt), j], color=models[model],
                    ls=LINESTYLES[fws[fw] % 4], lw=1, label=f"{model} ({fw})")
        ax.set_xlabel("time t (s)")
        ax.set_ylabel(f"q{j + 1} (rad or m)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Trajectory from one initial condition (first seed)")
    return save(fig, path)


def wave_spacetime(units: list[Unit], path: Path) -> bool:
    found = _first_with(units, ("x", "t", "field_true", "field_pred"))
    if not found:
        return False
    (model, fw), arr = next(iter(found.items()))
    x, t = np.asarray(arr["x"], float), np.asarray(arr["t"], float)
    true, pred = np.asarray(arr["field_true"], float), np.asarray(arr["field_pred"], float)
    fig, axes = new_figure(ncols=3, width=11, height=3.4, gap=1.7, right=1.0)
    extent = (x.min(), x.max(), t.max(), t.min())
    vmax = np.nanmax(np.abs(true)) or 1.0
    panels = [("truth", true, "RdBu_r", vmax), (f"{model} ({fw})", pred, "RdBu_r", vmax),
              ("prediction − truth", pred - true, "PuOr_r", np.nanmax(np.abs(pred - true)) or 1.0)]
    for ax, (name, field, cmap, lim) in zip(axes, panels, strict=True):
        im = ax.imshow(field, aspect="auto", extent=extent, cmap=cmap, vmin=-lim, vmax=lim)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("position x (m)")
        ax.set_ylabel("time t (s)")
        fig.colorbar(im, ax=ax, label="displacement u (m)")
    return save(fig, path)


def training_curves(units: list[Unit], path: Path) -> bool:
    curves = {}
    for key, group in _groups(units).items():
        logs = []
        for u in group:
            log = u.table("train_log.csv")
            if log is not None and {"step", "loss"} <= set(log.columns) and len(log):
                logs.append(log.groupby("step")["loss"].mean())
        if logs:
            curves[key] = logs
    if not curves:
        return False
    fig, (ax,) = new_figure(height=3.8)
    models = model_colours([k[0] for k in curves])
    fws = style_index([k[1] for k in curves])
    allv = []
    for (model, fw), logs in curves.items():
        idx = logs[0].index
        stack = np.vstack([s.reindex(idx).to_numpy(dtype=float) for s in logs])
        allv.extend(stack.ravel())
        ax.plot(idx.to_numpy(), np.nanmean(stack, 0), color=models[model],
                ls=LINESTYLES[fws[fw] % 4], label=f"{model} ({fw})")
    log_if_spread(ax, allv, decades=1.0)
    ax.set_xlabel("training step")
    ax.set_ylabel("training loss (mean over seeds)")
    ax.legend(fontsize=7, ncols=2)
    return save(fig, path)
