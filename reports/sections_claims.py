"""Summary, run-status and per-claim sections (grouped by :mod:`reports.themes`), with their figures.

``summary_sections(res)``, ``theme_sections(res, out_dir)`` (a page per claim) and ``claim_details(res)``
(the appendix's tables behind the claims' pages) return ``list[Section]``; figures are written under
``out_dir/figures/`` as ``<claim>_<kind>.png`` only when their data exist.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from lagbench.reports import figures as F
from lagbench.reports import figures_delan as FD
from lagbench.reports import figures_paper as FL
from lagbench.reports import figures_precision as FP
from lagbench.reports import figures_speed as FS
from lagbench.reports.document import NOT_RUN, Figure, Para, Section, Table
from lagbench.reports.fmt import cell, num
from lagbench.reports.load import Results
from lagbench.reports.scorecard import competence_table, parts_table
from lagbench.reports.tables import (
    PROBLEM_UNITS,
    claim_table,
    excluded_note,
    metrics_table,
    problem_units_table,
    status_table,
)
from lagbench.reports.themes import THEMES, assign

RESULT_FILES = "units/{claim}/<framework>/<model>/seed<k>/"
REASON_CHARS = 400   # a verdict's reason on a claim's page
# the paper figure a claim's figure recreates (the LNN paper's numbering, shared/seeds): same quantity and axes
PAPER_FIGURES = {("dp_energy", "energy"): "LNN Fig. 2(b) (energy of the double pendulum over a long time)",
                 ("dp_energy", "trajectory"): "LNN Fig. 2(a) (the double pendulum over a short time)",
                 ("rel_coords", "panels"): "LNN Fig. 3 (a)-(c) (the relativistic particle: HNN on non-canonical "
                                           "coordinates, HNN on canonical ones, LNN; trajectories over t in [0, 1])",
                 ("wave_lgn", "spacetime"): "LNN Fig. 4 (the wave equation learned by a Lagrangian graph network)",
                 ("wave_lgn", "wave_energy"): "LNN Fig. 4's statement that the graph network almost exactly conserves "
                                              "the energy integrated across the material",
                 ("hnn_energy", "energy"): "HNN Fig. 2's total-energy column (mass-spring, pendulum), drawn as the "
                                           "error against the truth's energy",
                 ("hnn_energy", "trajectory"): "HNN Fig. 2's first column (predicted trajectories), drawn against "
                                               "time rather than in phase space"}


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "claim"


def summary_sections(res: Results) -> list[Section]:
    s = Section("Summary")
    if not res.claims:
        s.add(Para("Nothing was run: the results folder holds no claims catalogue, verdicts or units."))
    n_ok = len(res.usable())
    s.add(Para(f"{len(res.claims)} claims catalogued; {len(res.units)} units found, {n_ok} usable "
               f"(status ok, checksums verified). Reproduced values are mean ± sample std over seeds "
               f"(n = seeds) of each claim's metric; numbers and verdicts are both recomputed from the "
               f"unit files. The scorecard shows each claim's key model; every model's numbers are in the "
               f"claim's own section."))
    st = Section("Run status", level=2)
    st.add(Table("Units per claim and framework", status_table(res), ["units/*/*/*/seed*/result.json"]))
    bad = problem_units_table(res)
    if bad is not None:
        st.add(Para(excluded_note("report")))
        st.add(Table(PROBLEM_UNITS, bad, ["units/*/*/*/seed*/result.json",
                                                                 "summary/units.csv"]))
    elif res.unfinished:
        st.add(Para("The run is unfinished (run.json records no end), though every unit it planned is present."))
    else:
        st.add(Para("No failed, corrupt or missing units."))
    if res.problems:
        st.add(Para("Problems reading the results: " + "; ".join(res.problems) + "."))
    return [s, st]


def _rollout_table(units) -> pd.DataFrame | None:
    frames = []
    for u in units:
        df = u.table("rollouts.csv")
        if df is not None and len(df):
            num_cols = [c for c in df.select_dtypes("number").columns if c not in ("traj", "seed")]
            if num_cols:
                frames.append(df[num_cols].mean().to_frame().T.assign(model=u.model, framework=u.framework))
    if not frames:
        return None
    all_ = pd.concat(frames, ignore_index=True)
    mean = all_.groupby(["model", "framework"], sort=False).mean(numeric_only=True)
    cols = list(mean.columns)[:6]
    rows = [{"model": m, "framework": fw, **{c: num(r[c]) if pd.notna(r[c]) else "not recorded" for c in cols}}
            for (m, fw), r in mean.iterrows()]
    return pd.DataFrame(rows)


def _published_energy(claim: dict) -> dict:
    """The published energy errors of a claim's models, with the conditions they were measured under."""
    out = {}
    for model, p in (claim.get("published") or {}).items():
        if isinstance(p, dict) and str(p.get("metric", "")).startswith("energy_err") and isinstance(p.get("value"), int | float):
            cond = ", ".join(f"{k} {v:g}" if isinstance(v, int | float) else f"{k} {v}"
                             for k, v in (p.get("conditions") or {}).items())
            out[model] = (float(p["value"]), f"{p.get('kind', 'published')}" + (f"; {cond}" if cond else ""))
    return out


def _paper_models(claim: dict) -> list[str]:
    """The models the claim's parts read (the paper's models), in the parts' order; its models where it has
    no parts."""
    read = [m for part in claim.get("parts") or [] for m in part.get("reads") or []]
    return list(dict.fromkeys(read or claim.get("models") or []))


def _brief(text: str, limit: int = REASON_CHARS) -> str:
    """A reason cut at a word for the claim's page; the parts table beside it and the appendix give it in full."""
    if len(text) <= limit:
        return text
    return text[:limit].rsplit(" ", 1)[0] + " … (in full: appendix, 'Reasons in full')"


def _trainings(units) -> tuple:
    """What identifies a claim's trainings: claims sharing them (the double pendulum's 1 and 2) share this."""
    return tuple(sorted((u.framework, u.model, u.seed, u.result.get("final_train_loss")) for u in units))


def claim_section(res: Results, claim: dict, out_dir: Path, drawn: dict | None = None,
                  details: dict | None = None) -> Section:
    """The claim's page: what it says and where, its verdict and parts, the decisive numbers against the
    published ones, then the figures that answer it. `drawn` maps the trainings whose work-precision figure is
    already in the report to its claim, so a figure of the same trainings is drawn once. The competence and
    rollout tables are the claim's details in the appendix (`claim_details`); so are its training curves
    where no work-precision figure stands in for them and the page has another figure, when `details`
    ({claim: [Figure]}) collects them."""
    cid = claim["id"]
    units = res.usable(cid)
    src = RESULT_FILES.format(claim=cid)
    s = Section(f"Claim {cell(claim.get('number'), '–')}: {cid}", level=2, page=True)
    s.add(Para(f"{cell(claim.get('title'), 'untitled')} — {cell(claim.get('paper'), 'paper unknown')} "
               f"{cell(claim.get('section'), '')}. System: {cell(claim.get('system'), 'unknown')}. "
               f"Metric: {cell(claim.get('metric'), 'unknown')} ({cell(claim.get('metric_label'), 'no label')}). "
               f"Verdict rule: {cell(claim.get('verdict_rule'), 'not stated')}. "
               f"Competence bars: {'; '.join(claim.get('bars') or []) or 'none (no learned model)'}."))
    v = res.verdicts.get(cid)
    if v is not None:
        kind = "check (not counted among the paper claims)" if v.get("kind") == "check" else "paper claim"
        s.add(Para(f"Verdict ({kind}): {cell(v.get('verdict'))}. {_brief(cell(v.get('reason'), ''))}"))
        for var in v.get("variants") or []:
            s.add(Para(f"Variant: {cell(var.get('name'))} ({cell(var.get('departure'))}): {cell(var.get('verdict'))}, "
                       f"{_brief(cell(var.get('reason'), ''))}. It does not decide the claim."))
    pt = parts_table(res, claim)
    if pt is not None:
        s.add(Table(f"{cid}: parts per framework", pt, [src + "result.json"],
                    note="Each part is decided on the interval shown; the last column gives the part's verdict "
                         "with the suite's own threshold (a factor, a band, a fraction, a level) halved and doubled."))
    if not units:
        s.add(Para(f"Result: {NOT_RUN} (no usable unit for this claim)."))
        return s
    s.add(Table(f"{cid}: {claim.get('metric', 'metric')} per model and framework", claim_table(res, claim),
                ["claims.json", src + "result.json"]))
    figs = [
        ("energy", lambda us, p: F.energy_drift(us, p, published=_published_energy(claim)),
         "|Energy error| over time against truth, log axis (line: median over seeds of each seed's median over its "
         "rollouts, band: seed range; diverged rollouts counted in the legend, not in the line; dotted: a published "
         "value, under the conditions its legend names)", "timeseries.csv"),
        ("panels", lambda us, p: FL.model_panels(us, p, _paper_models(claim)),
         "Velocity over time from three held-out initial states, one panel per paper model (first seed): truth "
         "(grey) against the model (dashed)", "arrays.npz"),
        ("trajectory", F.trajectory, "Trajectory: truth against each model", "arrays.npz"),
        ("spacetime", F.wave_spacetime, "Space-time image of the field: truth, model, difference", "arrays.npz"),
        ("wave_energy", FL.wave_energy, "Total energy of the pulse over time (line: median over seeds, band: seed "
                                        "range; diverged seeds counted in the legend, not drawn) and its error "
                                        "against the truth's, log axis", "timeseries.csv"),
        ("torques", FD.torque_traces, "Torque per joint on the unseen trajectories: truth against each model "
                                      "trained on the full data set (first seed)", "arrays.npz"),
        ("tracking", FD.tracking, "Computed-torque tracking at 500 Hz of the first unseen reference: each joint's "
                                  "reference against the executed angle, and the error's norm (log axis), per learned "
                                  "controller (first seed)", "arrays.npz"),
        ("online", FD.online_learning, "Learning online: each 0.5 s window's tracking MSE over PD alone's in the same "
                                       "window, against the seconds learned, one line per seed", "arrays.npz"),
        ("decomposition", FD.delan_decomposition, "Decomposition into inertial, Coriolis and gravity terms "
                                                 "(predicted against true)", "arrays.npz"),
        ("data_efficiency", lambda us, p: FS.data_efficiency(us, p, claim.get("metric")),
         "Data efficiency: error against training samples, log-log (bars: seed range)", "result.json"),
    ]
    done = set()
    for kind, fn, caption, file in figs:
        rel = f"figures/{slug(cid)}_{kind}.png"
        if kind == "trajectory" and "panels" in done:   # the per-model panels show the same rollouts
            continue
        if fn(units, out_dir / rel):
            done.add(kind)
            paper = PAPER_FIGURES.get((cid, kind))
            s.add(Figure(rel, f"{cid}: {caption}." + (f" It stands for {paper}." if paper else ""), [src + file]))
    drawn = {} if drawn is None else drawn
    key = _trainings(units)
    if key in drawn:
        s.add(Para(f"Training: the same trainings as {drawn[key]}'s; its training figure shows them."))
        return s
    rel = f"figures/{slug(cid)}_work_precision.png"
    if FP.work_precision(units, out_dir / rel):   # it shows the training curve; a separate one would repeat it
        drawn[key] = cid
        s.add(Figure(rel, f"{cid}: Work-precision: held-out loss against training samples and against training "
                          f"time (line: mean over seeds, band: seed range).", [src + "train_log.csv"]))
    elif F.training_curves(units, out_dir / (rel := f"figures/{slug(cid)}_training.png")):
        drawn[key] = cid
        fig = Figure(rel, f"{cid}: Training curves (mean over seeds).", [src + "train_log.csv"])
        if details is None or not done:   # the page's only figure stays on it
            s.add(fig)
        else:
            details.setdefault(cid, []).append(fig)
            s.add(Para("Training curves: in the appendix, with the claim's details."))
    return s


def claim_details(res: Results, figures: dict | None = None) -> list[Section]:
    """The appendix's tables behind each claim's page: competence bars per model and framework, and the
    rollout metrics (mean over trajectories and seeds); `figures` {claim: [Figure]} moved off its page."""
    out = []
    for claim in res.claims:
        cid = claim["id"]
        src = RESULT_FILES.format(claim=cid)
        d = Section(f"Claim {cell(claim.get('number'), '–')}: {cid}, details", level=2)
        ct = competence_table(res, claim)
        if ct is not None:
            d.add(Table(f"{cid}: competence bars per model and framework", ct, [src + "result.json"]))
        rt = _rollout_table(res.usable(cid)) if res.usable(cid) else None
        if rt is not None:
            d.add(Table(f"{cid}: rollout metrics (mean over trajectories and seeds)", rt, [src + "rollouts.csv"]))
        for fig in (figures or {}).get(cid, []):
            d.add(fig)
        if d.blocks:
            out.append(d)
    if not out:
        return []
    return [Section("Claim details").add(Para("The competence bars of every model and framework, and the rollout "
                                               "metrics, behind each claim's page.")), *out]


def metrics_appendix(res: Results) -> list[Section]:
    """Every metric each claim's units recorded (mean ± std over seeds): the dump behind the claims' tables."""
    s = Section("Appendix: all recorded metrics")
    for claim in res.claims:
        mt = metrics_table(res, claim) if res.usable(claim["id"]) else None
        if mt is not None:
            s.add(Table(f"{claim['id']}: all recorded metrics (mean ± std over seeds)", mt,
                        [RESULT_FILES.format(claim=claim["id"]) + "result.json"]))
    return [s] if s.blocks else []


def theme_sections(res: Results, out_dir: Path, details: dict | None = None) -> list[Section]:
    groups = assign(res.claims)
    out, drawn = [], {}
    for key, title, blurb, _ in THEMES:
        claims = groups[key]
        if key == "other" and not claims:
            continue
        s = Section(title).add(Para(blurb))
        if not claims:
            s.add(Para(f"Result: {NOT_RUN} (no claim of this kind in claims.json)."))
        out.append(s)
        pages = [claim_section(res, c, out_dir, drawn, details) for c in claims]
        if pages:
            pages[0].page = False   # the theme's first claim follows its heading on the same page
        out.extend(pages)
    return out
