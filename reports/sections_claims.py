"""Summary, run-status and per-claim sections (grouped by :mod:`reports.themes`), with their figures.

``summary_sections(res)``, ``theme_sections(res, out_dir)`` (a section per claim; a table note repeated from
claim to claim is said once) and ``claim_details(res)``
(the appendix's tables behind the claims' pages) return ``list[Section]``; figures are written under
``out_dir/figures/`` as ``<claim>_<kind>.png`` only when their data exist.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from lagbench.reports import figures as F
from lagbench.reports import figures_precision as FP
from lagbench.reports import glossary
from lagbench.reports.claim_figures import PAPER_FIGURES, figure_specs
from lagbench.reports.confounds import failing_seeds, model_sizes, not_tested, sizes_table
from lagbench.reports.document import NOT_RUN, Figure, Para, Section, Table
from lagbench.reports.fmt import cell, num
from lagbench.reports.load import Results
from lagbench.reports.reasons import did_not_learn, published_far, why_text
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


def _trainings(units) -> tuple:
    """What identifies a claim's trainings: claims sharing them (the double pendulum's 1 and 2) share this."""
    return tuple(sorted((u.framework, u.model, u.seed, u.result.get("final_train_loss")) for u in units))


def scouting_note(units) -> str:
    """Why a training log starts mid-budget: the models whose units scouted (several initialisations trained
    briefly, the best continued) log from the continuation on; "" where none did."""
    scouted = [u for u in units if isinstance(u.result.get("scouting"), dict)]
    if not scouted:
        return ""
    tried = len(scouted[0].result["scouting"].get("init_seeds") or [])
    models = ", ".join(dict.fromkeys(u.model for u in scouted))
    return (f" {models}: the log starts where the protocol's scouting ends ({tried or 'several'} initialisations "
            f"trained briefly, the best continued; the scouts' steps and samples count in the budget but are "
            f"not drawn), so their curves start mid-budget.")


def claim_section(res: Results, claim: dict, out_dir: Path, drawn: dict | None = None,
                  details: dict | None = None) -> Section:
    """The claim's page: what it says and where, its verdict (the reasons in words are the scorecard's), its
    parts, the decisive numbers against the published ones, what the comparison does not control (the
    compared models' sizes and budgets and every seed of a model below its bar go to the claim's details
    when `details` collects them), then the figures that answer it. `drawn` maps the trainings whose work-precision figure is already in the report to its claim, so a
    figure of the same trainings is drawn once. The competence and rollout tables are the claim's details in
    the appendix (`claim_details`); so are its training curves where no work-precision figure stands in for
    them and the page has another figure, when `details` ({claim: [Figure]}) collects them."""
    cid = claim["id"]
    units = res.usable(cid)
    src = RESULT_FILES.format(claim=cid)
    s = Section(f"Claim {cell(claim.get('number'), '–')}: {cid}", level=2)
    s.add(Para(f"{cell(claim.get('title'), 'untitled')} — {cell(claim.get('paper'), 'paper unknown')} "
               f"{cell(claim.get('section'), '')}. System: {cell(claim.get('system'), 'unknown')}. "
               f"Metric: {cell(claim.get('metric'), 'unknown')} ({cell(claim.get('metric_label'), 'no label')}). "
               f"Verdict rule: {cell(claim.get('verdict_rule'), 'not stated')}. "
               f"Competence bars: {'; '.join(claim.get('bars') or []) or 'none (no learned model)'}."))
    v = res.verdicts.get(cid)
    pt = parts_table(res, claim)
    if v is not None:
        kind = "check (not counted among the paper claims)" if v.get("kind") == "check" else "paper claim"
        # the reasons in words are the scorecard's (its why column); the page gives each part's interval (parts table)
        why = ("Why: the scorecard's row; each part with its interval: the table below." if units and pt is not None
               else why_text(res, claim) if units else cell(v.get("reason"), ""))
        s.add(Para(f"Verdict ({kind}): {cell(v.get('verdict'))}. {why}"))
        far, dead = published_far(res, claim), did_not_learn(res, claim)
        if far or dead:
            s.add(Para("Flags: " + "; ".join([f"far from published: {', '.join(far)}"] * bool(far)
                                              + [f"did not learn: {m} ({w})" for m, w in dead.items()]) + "."))
        for var in v.get("variants") or []:
            s.add(Para(f"Variant: {cell(var.get('name'))} ({cell(var.get('departure'))}): {cell(var.get('verdict'))}, "
                       f"{cell(str(var.get('reason') or '').split('. ', 1)[0], '')}. It does not decide the claim."))
    if pt is not None:
        s.add(Table(f"{cid}: parts per framework", pt, [src + "result.json"],
                    note="Each part is decided on the interval shown; the last column gives the part's verdict "
                         "with the suite's own threshold (a factor, a band, a fraction, a level) halved and doubled."))
    if not units:
        s.add(Para(f"Result: {NOT_RUN} (no usable unit for this claim)."))
        return s
    metric = claim.get("metric", "metric")
    u = glossary.unit(metric)
    s.add(Table(f"{cid}: {metric}{f' ({u})' if u and u != '–' else ''} per model and framework", claim_table(res, claim),
                ["claims.json", src + "result.json"],
                note="Seed mean (lowest to highest seed, n seeds); a yes/no metric as k/n seeds; every seed where "
                     "a model is below its competence bar. Published: like for like or context (what differs: "
                     "the appendix's published numbers)."))
    _confounds(s, res, claim, src, details)
    done = set()
    for kind, fn, caption, shows, file in figure_specs(res, claim):
        rel = f"figures/{slug(cid)}_{kind}.png"
        if kind == "trajectory" and "panels" in done:   # the per-model panels show the same rollouts
            continue
        got = fn(units, out_dir / rel)
        if got:
            done.add(kind)
            s.add(Figure(rel, f"{cid}: {caption(got)}.", [src + file], shows=shows,
                         paper=PAPER_FIGURES.get((cid, kind), "")))
    drawn = {} if drawn is None else drawn
    key = _trainings(units)
    if key in drawn:
        s.add(Para(f"Training: the same trainings as {drawn[key]}'s; its training figure shows them."))
        return s
    rel = f"figures/{slug(cid)}_work_precision.png"
    if (first := FP.work_precision(units, out_dir / rel)):   # it shows the training curve; a separate one would repeat it
        drawn[key] = cid
        s.add(Figure(rel, f"{cid}: Work-precision: each model's own training loss measured on held-out states, "
                          f"against training samples and against training time (line: mean over seeds, band: seed "
                          f"range). Both axes are logarithmic, so they start at the first tracked point "
                          f"({num(first)} samples), not at zero.{scouting_note(units)}", [src + "train_log.csv"],
                     shows="held-out value of each model's own training loss (not comparable across model kinds) "
                           "against training samples and training time (s)"))
    elif F.training_curves(units, out_dir / (rel := f"figures/{slug(cid)}_training.png")):
        drawn[key] = cid
        fig = Figure(rel, f"{cid}: Training curves (mean over seeds), from the first logged step."
                          f"{scouting_note(units)}",
                     [src + "train_log.csv"], shows="training loss (each model's own loss function) against step")
        if details is None or not done:   # the page's only figure stays on it
            s.add(fig)
        else:
            details.setdefault(cid, []).append(fig)
            s.add(Para("Training curves: in the appendix, with the claim's details."))
    return s


def _confounds(s: Section, res: Results, claim: dict, src: str, details: dict | None = None) -> None:
    """What the comparison does not control: the rule's blind spots on the page, with the compared models'
    sizes and budgets and every seed of a model below its competence bar (the page's claim table gives each
    such seed's value), on the page or, when `details` ({claim: [block]}) collects them, in the claim's
    details."""
    sizes = model_sizes(res, claim)
    table = sizes_table(res, claim, sizes)
    seeds = failing_seeds(res, claim)
    blocks = [Table(f"{claim['id']}: the compared models' sizes and budgets", table, [src + "result.json"],
                    note="Parameters counted from each unit's recorded model spec (median over seeds of training "
                         "samples and seconds).")] if table is not None else []
    if seeds is not None:
        blocks.append(Table(f"{claim['id']}: every seed of a model below its competence bar", seeds,
                            [src + "result.json"]))
    text = "Not tested by the rule: " + not_tested(res, claim, sizes)
    if details is None or not blocks:
        s.add(blocks[0] if table is not None else None, Para(text), *blocks[table is not None:])
        return
    details.setdefault(claim["id"], []).extend(blocks)
    s.add(Para(text + " The models' sizes and budgets" + (" and every seed below its bar" if seeds is not None else "")
               + ": the claim's details, in the appendix."))


def claim_details(res: Results, figures: dict | None = None) -> list[Section]:
    """The appendix's tables behind each claim's page: competence bars per model and framework, and the
    rollout metrics (mean over trajectories and seeds); `figures` {claim: [Table or Figure]} moved off its page."""
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
        out.extend(claim_section(res, c, out_dir, drawn, details) for c in claims)
    seen: set = set()
    for b in (b for s in out for b in s.blocks if isinstance(b, Table) and b.note):   # a note is said once
        if b.note in seen:
            b.note = ""
        else:
            seen.add(b.note)
    return out
