"""The fit report's paragraphs: what a `lagbench fit` or `lagbench evaluate` folder's models were trained on,
what each fit chose from its data, which are no better than the null predictor, and which fit to use.

``unit_name(u)``: a unit as the fit report names it. ``data_para(units)``: each file's rows and trajectories
and how derivatives it lacked were estimated (``eval_config``). ``choices_para(units)``: the periodic inputs,
dissipation, even Lagrangian and loss each fit chose, with the reasons. ``competence_para(units)``: the fits
not clearly better than the null predictor. ``recommendation_para(units)``: the fewest parameters within
``RECOMMEND_WITHIN`` x the best rollout error.
"""
from __future__ import annotations

import numpy as np

from lagbench.reports.document import Para
from lagbench.reports.fmt import cell, count, num

SETS = {"train": "train", "heldout": "held-out", "test": "test"}


def unit_name(u) -> str:
    return f"{u.model} ({u.framework}, seed {u.seed})"


def _competence(u) -> dict | None:
    """`replication.fit.competence.competence` of the unit on the set it reports: the test file's, else held-out."""
    from lagbench.replication.fit.competence import competence

    m, loss = u.result.get("metrics") or {}, (u.result.get("protocol") or {}).get("loss", "l1")
    return next((c for c in (competence(m, f"{s}_{loss}") for s in ("test", "heldout")) if c is not None), None)


def competence_para(units) -> Para | None:
    """The fits and evaluations not clearly better than the null predictor on the set they report, named."""
    from lagbench.replication.fit.competence import describe

    flagged = [f"{unit_name(u)} ({u.claim}), {c['metric']}: {describe(c)}" for u in units
               if (c := _competence(u)) is not None and not c["learned"]]
    if not flagged:
        return None
    return Para("Not clearly better than the null predictor (at most half its error): " + "; ".join(flagged) + ".")


RECOMMEND_WITHIN = 2.0   # the recommendation: the fewest parameters among the fits within this x the best rollout error


def recommendation_para(units) -> Para | None:
    """The fit to use on this data: among the fits that learned, the one with the fewest parameters whose
    rollout error (test file, else held-out) is within RECOMMEND_WITHIN x the best; None with fewer than two."""
    from lagbench.reports.systems_table import params_of

    cands = []
    for u in units:
        err = u.metric("test_rollout_gmean_err")
        err = u.metric("heldout_rollout_gmean_err") if err is None else err
        if u.claim == "fit" and err is not None and np.isfinite(err) and (_competence(u) or {}).get("learned"):
            cands.append((err, params_of(u), unit_name(u)))
    if len(cands) < 2:
        return None
    best = min(cands)
    pick = min((c for c in cands if c[0] <= RECOMMEND_WITHIN * best[0]), key=lambda c: (c[1], c[0]))
    return Para(f"Recommended on this data: {pick[2]} (rollout error {num(pick[0])}, {count(pick[1])} parameters), the "
                f"fewest parameters among the fits within {RECOMMEND_WITHIN:g} x the best rollout error ({best[2]}: "
                f"{num(best[0])}); fits not clearly better than the null predictor are left out.")


def _path(ref) -> str:
    return str(ref or "").removeprefix("file:").split("#sha256=")[0]


def data_para(units) -> Para:
    from lagbench.replication.fit.derivative_window import describe
    from lagbench.replication.fit.rows import Overlap

    seen: dict[str, list[str]] = {}
    for u in units:
        cfg = u.result.get("eval_config") or {}
        src = _path(cfg.get("source"))
        d = cfg.get("derivatives") or {}
        traj = cfg.get("trajectories") or {}
        rows = cfg.get("rows") or {}
        split = " / ".join(f"{rows[k]} {SETS[k]}" for k in SETS if k in rows)
        whole = " / ".join(f"{traj[k]}" for k in SETS if traj.get(k))
        text = (f"{cell(src, 'unknown file')}: {split} rows"
                + (f" ({whole} whole trajectories); derivatives the file lacked estimated by Savitzky–Golay "
                   f"({describe(d)})" if any(traj.values()) else "")
                + (f"; test file {_path(cfg['test_source'])}: {cfg.get('test_rows')} rows"
                   + (f" ({cfg['test_trajectories']} whole trajectories)" if cfg.get("test_trajectories") else "")
                   + (f", its derivatives by the same rule ({describe(cfg['test_derivatives'])})"
                      if cfg.get("test_derivatives") else "")
                   if cfg.get("test_source") else "")
                + (f"; WARNING: {Overlap(**cfg['training_rows']).words()} are training rows of the fit evaluated, "
                   f"so its errors there are not predictions of unseen data" if cfg.get("training_rows") else "")
                + (f"; true energy from system {cfg['system']}" if cfg.get("system") else "")
                + (f"; true energy from {cfg['energy']}" if cfg.get("energy") else ""))
        seen.setdefault(text, []).append(f"{u.claim} {unit_name(u)}")
    return Para("Data: " + " | ".join(f"{text} ({', '.join(names)})" for text, names in seen.items()) + ".")


def choices_para(units) -> Para | None:
    """What each fit chose from its data and system: its periodic inputs (`--periodic`), whether it learns a
    dissipation (`--dissipation`), whether its Lagrangian is even in q-dot (`--even-velocity`, recorded where
    on) and the loss `--loss-target auto` chose where not the acceleration loss, with the reasons; None where no
    fit recorded any."""
    from lagbench.replication.fit import energy_trend, even_velocity, loss_target, periodic_coords

    seen: dict[str, list[str]] = {}
    for u in units:
        cfg = u.result.get("eval_config") or {}
        parts = ([f"periodic inputs {periodic_coords.describe(cfg['periodic'])}"] if cfg.get("periodic") else []) + \
            ([f"dissipation {energy_trend.describe(cfg['dissipation'])}"] if cfg.get("dissipation") else []) + \
            ([f"Lagrangian even in q-dot {even_velocity.describe(cfg['even_velocity'])}"] if cfg.get("even_velocity")
             else []) + \
            ([f"loss {loss_target.describe(cfg['loss_target'])}"] if cfg.get("loss_target") else [])
        if u.claim == "fit" and parts:
            seen.setdefault("; ".join(parts), []).append(unit_name(u))
    if not seen:
        return None
    return Para("Chosen for the data: " + " | ".join(f"{', '.join(names)}: {text}" for text, names in seen.items())
                + ".")
