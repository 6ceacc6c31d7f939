"""The robustness study's figure: `advantage_figure(df, path)` draws, from the scenes table
(`robustness.COLUMNS`), DeLaN's error over the feed-forward net's against the violation's magnitude, one
column per scene kind (the nominal scene is each kind's magnitude 0), torque error above, tracking error
below; one line per DeLaN variant and framework (the median over seeds), log ratio axis shared along a
row, the line ratio 1 where DeLaN has no advantage left. ``colours`` ({variant: colour}, e.g. the report's
colour per model) gives each variant its colour, else matplotlib's first two (blue, orange: told apart
under the common colour-vision deficiencies, and by line style and marker). matplotlib without pyplot (Agg
via savefig)."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.files.results import atomic_write_bytes
from lagbench.replication.studies.robustness_scenes import KINDS, UNITS

VARIANTS = {"delan": ("DeLaN / ff", "-", "o"), "delan_dissipation": ("DeLaN + dissipation / ff", "--", "s")}
ROWS = (("torque_ratio_to_ff", "torque nMSE ratio"), ("track_ratio_to_ff", "tracking MSE ratio"))


def advantage_figure(df: pd.DataFrame, path, colours: dict[str, str] | None = None) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.0 * len(KINDS), 5.6))
    axes = fig.subplots(len(ROWS), len(KINDS), squeeze=False, sharey="row")
    nominal = df[df["kind"] == "nominal"]
    for j, kind in enumerate(KINDS):
        g = pd.concat([nominal, df[df["kind"] == kind]])
        for i, (col, label) in enumerate(ROWS):
            ax = axes[i, j]
            for (model, fw), m in g[g["model"].isin(list(VARIANTS))].groupby(["model", "framework"]):
                med = m.groupby("magnitude")[col].median()
                name, style, marker = VARIANTS[model]
                ax.plot(med.index, med.to_numpy(), style, marker=marker, label=f"{name} ({fw})",
                        color=(colours or {}).get(model, f"C{list(VARIANTS).index(model)}"))
            ax.axhline(1.0, color="0.5", lw=0.8)
            if np.isfinite(g[col]).any() and (g[col] > 0).any():
                ax.set_yscale("log")
            ax.set_xlabel(f"{kind.replace('_', ' ')} ({UNITS[kind]})" if i == len(ROWS) - 1 else "")
            ax.set_ylabel(label if j == 0 else "")
            if i == 0:
                ax.set_title(kind.replace("_", " "))
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("DeLaN's error / the feed-forward net's (below 1: DeLaN better)", fontsize=10)
    fig.subplots_adjust(left=0.085, right=0.98, bottom=0.1, top=0.88, wspace=0.3, hspace=0.3)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    atomic_write_bytes(Path(path), buf.getvalue())
