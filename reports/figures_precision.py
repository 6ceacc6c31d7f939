"""Work-precision: each model's held-out loss against the training samples it used and the training time
it took (the SciML work-precision view of speed against error).

``work_precision(units, path)`` reads the tracked rows of ``train_log.csv`` (``samples``, ``train_s``,
``heldout_loss``: `replication.training.tracking`, present where the protocol sets ``tracking``). Per model and
framework, the seeds share their tracking steps: the line is the mean over seeds of the held-out loss
(plotted against the samples, and against the mean training seconds), the band the seed range. The held-out
loss is each model's own training loss (its protocol's data loss) on held-out states, so it compares a model
with itself over training, not models of different kinds; the axis says so. Returns the samples of the first
tracked point drawn (the log axes start there, not at zero), or 0 when nothing was drawn.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.ticker import FuncFormatter, NullFormatter

from lagbench.reports.figures import (
    LINESTYLES,
    _groups,
    model_colours,
    new_figure,
    save,
    style_index,
)
from lagbench.reports.load import Unit

MINOR_LABELS = (2, 3, 5, 7)   # mantissas labelled on a log axis within one decade: at least 0.14 decade apart


def label_minor_log(ax, axis: str = "x") -> None:
    """On a log axis spanning less than a decade (where the minor ticks carry the only labels), label the
    minor ticks at `MINOR_LABELS` x a power of ten alone, so that no two labels run into each other."""
    def text(v: float, _pos) -> str:
        if not (np.isfinite(v) and v > 0):
            return ""
        e = int(np.floor(np.log10(v) + 1e-9))
        m = int(round(v / 10.0 ** e))
        return f"${m}\\times10^{{{e}}}$" if m in MINOR_LABELS and abs(v - m * 10.0 ** e) < 1e-6 * v else ""
    (ax.xaxis if axis == "x" else ax.yaxis).set_minor_formatter(FuncFormatter(text))


COLUMNS = {"samples", "train_s", "heldout_loss"}


def tracked(units: list[Unit]) -> dict[tuple[str, str], pd.DataFrame]:
    """{(model, framework): rows per tracking step: samples, train_s (mean), loss mean, lo, hi, n seeds}."""
    out = {}
    for key, group in _groups(units).items():
        frames = []
        for u in group:
            log = u.table("train_log.csv")
            if log is not None and COLUMNS <= set(log.columns):
                t = log.dropna(subset=["heldout_loss"])[["step", *sorted(COLUMNS)]]
                if len(t):
                    frames.append(t)
        if frames:
            g = pd.concat(frames).groupby("step")
            out[key] = pd.DataFrame({"samples": g["samples"].mean(), "train_s": g["train_s"].mean(),
                                     "mean": g["heldout_loss"].mean(), "lo": g["heldout_loss"].min(),
                                     "hi": g["heldout_loss"].max(), "n": g["heldout_loss"].count()})
    return out


def work_precision(units: list[Unit], path: Path) -> float:
    curves = tracked(units)
    if not curves:
        return 0.0
    fig, axes = new_figure(ncols=2, width=9.0, height=3.6)
    models = model_colours([k[0] for k in curves])
    fws = style_index([k[1] for k in curves])
    for ax, x, label in ((axes[0], "samples", "training samples"), (axes[1], "train_s", "training time (s)")):
        xs = []
        for (model, fw), d in curves.items():
            d = d[(d[x] > 0) & np.isfinite(d["mean"]) & (d["mean"] > 0)]
            if not len(d):
                continue
            xs.extend(d[x])
            c = models[model]
            ax.plot(d[x], d["mean"], color=c, ls=LINESTYLES[fws[fw] % 4], label=f"{model} ({fw})")
            ax.fill_between(d[x], d["lo"], d["hi"], color=c, alpha=0.15, lw=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        if xs and max(xs) >= 10 * min(xs):   # within one decade the minor ticks carry the only labels
            ax.xaxis.set_minor_formatter(NullFormatter())
        else:
            label_minor_log(ax)
        ax.set_xlabel(label)
    axes[0].set_ylabel("model's own training loss,\non held-out states")
    axes[0].legend(fontsize=7)
    starts = [float(d.loc[d["samples"] > 0, "samples"].min()) for d in curves.values() if (d["samples"] > 0).any()]
    if not starts:
        return 0.0
    save(fig, path)
    return min(starts)
