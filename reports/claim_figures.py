"""The figures a claim's page can hold, each with the caption it gets, what it shows (the quantity on its axes)
and the result file it is drawn from, and the paper figure it recreates (``PAPER_FIGURES``).

``figure_specs(res, claim) -> [(kind, draw, caption, shows, file)]``: ``draw(units, path)`` writes the figure
and returns what it drew (truthy; the panels, where it says) or nothing; ``caption(drawn)`` words it from what
was drawn, so a caption never names a panel the figure lacks. The energy figure draws a published value only
where it is measured like for like (``like_for_like``: the same kind, conditions, widths and budget); a
published value that is context only is named in the caption and not drawn.
"""
from __future__ import annotations

from lagbench.reports import figures as F
from lagbench.reports import figures_delan as FD
from lagbench.reports import figures_paper as FL
from lagbench.reports import figures_speed as FS
from lagbench.reports.fmt import num
from lagbench.reports.load import Results
from lagbench.reports.tables import like_for_like

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


def published_energy(res: Results, claim: dict) -> tuple[dict, list[str]]:
    """({model: (value, conditions)} of the published energy errors measured like for like, drawn in the energy
    figure; [words] of those that are context only, named in its caption and not drawn)."""
    drawn, context = {}, []
    for model, p in (claim.get("published") or {}).items():
        if isinstance(p, dict) and str(p.get("metric", "")).startswith("energy_err") and isinstance(p.get("value"), int | float):
            cond = ", ".join(f"{k} {v:g}" if isinstance(v, int | float) else f"{k} {v}"
                             for k, v in (p.get("conditions") or {}).items())
            same, _ = like_for_like(p, [u for u in res.usable(claim["id"]) if u.model == model])
            if same:
                drawn[model] = (float(p["value"]), f"{p.get('kind', 'published')}" + (f"; {cond}" if cond else ""))
            else:
                context.append(f"{model} {num(p['value'])}" + (f" ({cond})" if cond else ""))
    return drawn, context


def paper_models(claim: dict) -> list[str]:
    """The models the claim's parts read (the paper's models), in the parts' order; its models where it has
    no parts."""
    read = [m for part in claim.get("parts") or [] for m in part.get("reads") or []]
    return list(dict.fromkeys(read or claim.get("models") or []))


def figure_specs(res: Results, claim: dict) -> list:
    """(kind, draw(units, path), caption(drawn), shows, file) of each figure a claim's page can hold; `drawn` is
    what the drawing returned (the panels it drew, where it says)."""
    published, context = published_energy(res, claim)
    dotted = ("; dotted: a published value measured like for like, under the conditions its legend names"
              if published else "")
    untouched = (f"; published values that are context only are not drawn ({', '.join(context)})" if context else "")
    metric = claim.get("metric") or "the claim's metric"

    def fixed(text):
        return lambda drawn: text
    return [
        ("energy", lambda us, p: F.energy_drift(us, p, published=published),
         fixed("|Energy error| over time against truth, log axis (line: median over seeds of each seed's median "
               f"over its rollouts, band: seed range; diverged rollouts counted in the legend, not in the line"
               f"{dotted}{untouched})"), "|energy error| relative to the energy scale, against time t (s)",
         "timeseries.csv"),
        ("panels", lambda us, p: FL.model_panels(us, p, paper_models(claim)),
         lambda drawn: (f"Velocity over time from three held-out initial states, one panel per paper model drawn "
                        f"({', '.join(drawn)}; first seed): truth (grey) against the model (dashed)"),
         "velocity q̇ (units of c) against time t (s)", "arrays.npz"),
        ("trajectory", F.trajectory, fixed("Trajectory: truth against each model"),
         "coordinates q against time t (s)", "arrays.npz"),
        ("spacetime", F.wave_spacetime, fixed("Space-time image of the field: truth, model, difference"),
         "displacement u (m) over position x and time t", "arrays.npz"),
        ("wave_energy", FL.wave_energy, fixed("Total energy of the pulse over time (line: median over seeds, band: "
                                              "seed range; diverged seeds counted in the legend, not drawn) and "
                                              "its error against the truth's, log axis"),
         "total energy E, and |E_model - E_true| / E_true(0), against time t (s)", "timeseries.csv"),
        ("torques", FD.torque_traces, fixed("Torque per joint on the unseen trajectories: truth against each model "
                                            "trained on the full data set (first seed)"),
         "torque per joint (N m) against the sample index", "arrays.npz"),
        ("tracking", FD.tracking, fixed("Computed-torque tracking at 500 Hz of the first unseen reference: each "
                                        "joint's reference against the executed angle, and the error's norm (log "
                                        "axis), per learned controller (first seed)"),
         "joint angles (rad) and |q - q_ref| (rad) against time (s)", "arrays.npz"),
        ("online", FD.online_learning, fixed("Learning online: each 0.5 s window's tracking MSE over PD alone's in "
                                             "the same window, against the seconds learned, one line per seed"),
         "window tracking MSE / PD alone's against the time learning online (s)", "arrays.npz"),
        ("decomposition", FD.delan_decomposition,
         lambda drawn: f"Decomposition into the terms drawn ({', '.join(drawn)}): predicted against true",
         "predicted against true torque terms (SI units)", "arrays.npz"),
        ("data_efficiency", lambda us, p: FS.data_efficiency(us, p, claim.get("metric")),
         fixed("Data efficiency: error against training samples, log-log (bars: seed range)"),
         f"{metric} against training samples N", "result.json"),
    ]
