"""The report's glossary: every term the scorecard uses and every metric name its tables show, with its unit.

``TERMS``: (term, definition) in the order a reader meets them on the scorecard. ``define(name)`` ->
(meaning, unit) of a metric name, or None: exact names (``METRICS``), then the suite's naming rules (a
``null_`` prefix: the null predictor's; ``matched_``: read at matched accuracy; ``chaos_floor_``: the
truth's own from perturbed starts; a fit's set prefix ``heldout_``/``test_``; a ``_joint<j>`` suffix; a
family suffix ``_train``, ``_test``, ``_train_x2``; an aggregate suffix ``_median``, ``_finite``, ``_q25``,
``_q75``). ``unit(name)``: the unit alone ("" when unknown). ``metric_names(sections)``: the metric names the
tables show (column headers and the "key number" cells). ``glossary_section(sections)``: the section that
follows the scorecard (the terms, then a table of the metric names used).
"""
from __future__ import annotations

import re

import pandas as pd

from lagbench.replication.evaluation.diverged import DIVERGED
from lagbench.reports.document import Bullets, Para, Section, Table

Q = "units of q̈"
TERMS = [
    ("reproduced / not reproduced", "every counted part of the claim held / none did, each decided on the "
                                    "confidence interval of its rule"),
    ("partly", "only: the named parts reproduced and the others did not"),
    ("inconclusive", "at least one part is undecided: a model below its competence bar, the interval straddling "
                     "the threshold, a failed seed, frameworks that disagree, or a model that did not run"),
    ("part", "one separately decidable statement of a claim, decided per framework by its rule"),
    ("check", "a statement about the implementation or the numerics (a null model passes it too): shown, never "
              "counted among the claims"),
    ("variant", "a model with a departure from the paper standing in for the paper's model; its verdict is its "
                "own line and never decides a claim"),
    ("competence bar", "what a model must show on every seed before a claim about it is judged: its error on "
                       "its own training distribution at most a set fraction (usually 0.1) of the null "
                       "predictor's, and rollouts that do not diverge where the claim reads rollouts"),
    ("null predictor", "the better of two predictors that learned nothing (predicting zero, predicting the "
                       "held-out mean target); a model at its error has not learned"),
    ("did not learn", "the model's error was at least half the null predictor's on every seed, or its training "
                      "loss stayed flat (last logged at least 0.9 x the first)"),
    ("positive control", "a model the same pipeline must teach for a failure to count: a part whose control is "
                         "below its bar is inconclusive"),
    ("interval", "the 90 % confidence interval over seeds of the ratio a rule reads (Welch's t on log ratios; "
                 "a Hodges-Lehmann interval where a seed diverged), wider with fewer seeds; one seed gives none"),
    ("threshold", "the value a rule reads its interval against (a factor of 1.5 reads 1/1.5 = 0.667)"),
    ("straddles the threshold", "the interval holds the threshold: the seeds cannot tell, the part is inconclusive"),
    ("near the threshold", "decided, but the interval's nearer end lies within 25 % of the threshold"),
    ("decided", "the interval lies wholly on one side of the threshold (or every seed inside a bound)"),
    ("k/n seeds", "on k of the n seeds (a bar passed, or a yes/no metric such as left_plateau)"),
    ("mean (low to high, n seeds)", "the seed mean and the range over seeds"),
    ("±", "the sample standard deviation over seeds (n - 1 in the denominator), with n the seed count"),
    ("like for like / context", "a published number is like for like only when it is the same kind of number "
                                "measured under the same conditions (widths, samples, evaluation); otherwise it "
                                "is context, never a target"),
    ("far from published", "a seed mean more than 2x, or under half, the published value of the same metric"),
    ("sizes differ", "the parameter counts of the models one part compares differ by more than 1.5x (a confound "
                     "the rule does not control)"),
    ("development draw / split", "seeds from 0 and data draws that protocols were tuned on; the test split "
                                 "(seeds from 1000, draws no choice read) decides the verdicts of record"),
    ("diverged", f"a rollout whose error against the data's own scale (energy error over the mean kinetic energy, "
                 f"state error over the states' spread) became non-finite or exceeded {DIVERGED:g}; counted apart, "
                 f"never averaged in"),
    ("frameworks disagree", "JAX and PyTorch, from the same weights and batches, reach different decided verdicts "
                            "on a part: a defect, and the part reads inconclusive"),
]

METRICS = {
    "heldout_l1": ("held-out error: mean over held-out states of the L1 norm of predicted minus true q̈", Q),
    "heldout_mse": ("held-out mean squared error of q̈", "squared units of q̈"),
    "heldout_l1_qddot": ("held-out (1 + γ)-weighted L1 error of q̈ (relativistic particle)", "units of c per s"),
    "heldout_l1_per_node": ("held-out L1 error of q̈ per grid node (wave)", Q),
    "transfer_l1_per_node": ("L1 error of q̈ per node on the 100-point grid of a model trained on 10 points", Q),
    "transfer_ratio": ("transfer_l1_per_node over heldout_l1_per_node", "–"),
    "final_train_loss": ("the last logged training loss (each model's own loss function)", "the model's loss"),
    "left_plateau": ("1 if a seed's held-out L1 is off the q̈ ≈ 0 plateau at the end of the budget, else 0; "
                     "its mean is a share of seeds", "share"),
    "energy_err": ("|E_pred - E_true| over the energy scale, along a rollout", "–"),
    "energy_err_final": ("|E_pred(T) - E_true(T)| over the energy scale at the final time T, mean over initial "
                         "states (a diverged rollout counts +inf)", "–"),
    "energy_err_max": ("largest |E_pred - E_true| over the energy scale along a rollout, mean over initial "
                       "states", "–"),
    "energy_err_vs_truth_max": ("largest |E_model - E_true| / E_true(0) over time (wave)", "–"),
    "truth_energy_drift_final": ("the ground truth's own |E(T) - E(0)| over the energy scale, integrated in the "
                                 "model's dtype", "–"),
    "truth_energy_drift_max": ("largest truth_energy_drift over time", "–"),
    "truth_energy_drift_worst": ("truth_energy_drift_final of the worst initial state", "–"),
    "truth_energy_drift_f64ref": ("truth_energy_drift_final of the float64 ground truth used everywhere else", "–"),
    "gmean_err": ("geometric mean over time of a rollout's state error against the truth", "state units"),
    "final_err": ("a rollout's state error against the truth at its end", "state units"),
    "state_err": ("a rollout's state error against the truth", "state units"),
    "state_err_gm": ("geometric mean over time of a rollout's state error", "state units"),
    "rollout_gmean_err": ("mean over initial states of gmean_err", "state units"),
    "rollout_final_err": ("mean over initial states of final_err", "state units"),
    "vpt_s": ("valid prediction time: median over initial states of the first time the state's normalised "
              "RMSE exceeds 0.4", "s"),
    "vpt_nmse_s": ("valid prediction time under normalised MSE 0.025 (the other convention in use)", "s"),
    "vpt_censored": ("share of initial states whose prediction stayed valid to the horizon", "share"),
    "vpt_lyapunov": ("vpt_s in Lyapunov times", "Lyapunov times"),
    "lyapunov_time_s": ("1 / the largest Lyapunov exponent, estimated from the truth and a start 1e-8 away", "s"),
    "float32_truth_vpt_s": ("valid prediction time of the truth integrated in float32 (the float32 floor)", "s"),
    "rollout_us_per_step": ("wall time per integration step of a rollout", "µs"),
    "n_diverged": ("rollouts (or references) that diverged", "count"),
    "n_diverged_ticks": ("control ticks after which the tracking diverged", "count"),
    "n": ("count of values", "count"),
    "max_abs_err": ("largest |q̈ - (-g, 0)| over random states (the exact free-fall Lagrangian)", "m/s²"),
    "max_abs_err_vs_sympy": ("largest |q̈| difference from the SymPy derivation", "m/s²"),
    "torque_mse": ("mean squared torque error", "(N m)²"),
    "torque_effort": ("mean squared feed-forward torque", "(N m)²"),
    "tracking_mse": ("mean over references and time of |q - q_ref|², computed-torque control at 500 Hz", "rad²"),
    "truth_tracking_mse": ("tracking_mse of the true inverse dynamics (the best any model can do)", "rad²"),
    "inertial_mse": ("mean squared error of the predicted inertial torque M(q) q̈", "(N m)²"),
    "coriolis_mse": ("mean squared error of the predicted Coriolis and centrifugal torque", "(N m)²"),
    "gravity_mse": ("mean squared error of the predicted gravity torque", "(N m)²"),
    "mass_matrix_min_eig": ("smallest eigenvalue of the learned mass matrix over the states", "kg m²"),
    "t_reach_s": ("seconds learning online until the 0.5 s windows' tracking MSE stays at most 0.1 x PD "
                  "alone's for 5 s (+inf: never)", "s"),
    "tail_mse": ("mean tracking MSE of the last windows while learning online", "rad²"),
    "first_window_mse": ("tracking MSE of the first 0.5 s window while learning online", "rad²"),
    "final_window_mse": ("tracking MSE of the last 0.5 s window while learning online", "rad²"),
    "final_ratio_to_pd": ("final_window_mse over PD alone's in the same window", "–"),
    "unseen_mse": ("tracking MSE on unseen references after learning online", "rad²"),
    "unseen_ratio_to_pd": ("unseen_mse over PD alone's", "–"),
    "unseen_diverged": ("unseen references that diverged", "count"),
    "compute_us_mean": ("mean compute per control tick", "µs"),
    "compute_us_p99": ("99th percentile of the compute per control tick", "µs"),
    "inference_us_mean": ("mean time of one model evaluation in the control loop", "µs"),
    "match_level": ("the held-out error level at which two models are read (matched accuracy)", Q),
    "matched_samples": ("training samples at which the model reached the matched level", "samples"),
    "matched_tracked_l1": ("the tracked held-out loss the matched checkpoint was chosen by", "the model's loss"),
    "l1": ("mean L1 error of q̈ over the set's states", Q),
    "mse": ("mean squared error of q̈ over the set's states", "squared units of q̈"),
    "learned_energy_drift": ("drift of the model's own learned energy along its rollout", "–"),
    "decomposition_scale": ("least-squares factor between the learned and the true M, c and g", "–"),
    "dissipation_scale": ("least-squares factor of the learned Hessian against the true mass matrix", "–"),
    "dissipation_hessian_residual": ("relative residual of that fit", "–"),
    "dissipation_ablation": ("one-step error without the learned dissipation over that with it", "–"),
    "dissipation_bracket_half": ("rollout error with every learned friction coefficient halved over that with the "
                                 "learned ones", "–"),
    "dissipation_bracket_double": ("rollout error with every learned friction coefficient doubled over that with "
                                   "the learned ones", "–"),
    "mass_matrix_rel_err": ("mean relative error of the learned mass matrix", "–"),
    "coriolis_rel_err": ("mean relative error of the learned Coriolis term", "–"),
    "gravity_rel_err": ("mean relative error of the learned gravity term", "–"),
    "energy_scale": ("the energy scale errors are divided by", "J"),
    "samples_per_s": ("samples processed per second", "samples/s"),
    "steps_per_s": ("optimiser steps per second", "steps/s"),
    "seconds_per_eval": ("wall time of one evaluation", "s"),
    "wall_s": ("wall time", "s"),
    "n_steps": ("accepted integration steps per trajectory, mean over the trajectories", "count"),
    "mean_us": ("mean compute per control tick (the measured ticks, after the warm-up)", "µs"),
    "median_us": ("median compute per control tick", "µs"),
    "p99_us": ("99th percentile of the compute per control tick", "µs"),
    "rate_hz_mean": ("control ticks per second the mean compute sustains (1e6 / mean_us)", "Hz"),
    "rate_hz_p99": ("control ticks per second the 99th-percentile compute sustains (1e6 / p99_us)", "Hz"),
    "fits_500hz_mean": ("whether the mean compute per tick is below the 2 ms period of a 500 Hz loop", "yes/no"),
    "learning_us_mean": ("mean time of the learning step per control tick (0 where the model only infers)", "µs"),
    "jax_dispatch": ("JAX's dispatch during the timing: async (the default) or sync", "–"),
    "us_per_sample": ("microseconds per sample of the fastest call on a batch of random states", "µs"),
    "fits_500hz_p99": ("whether the 99th-percentile compute per tick is below the 2 ms period of a 500 Hz loop",
                       "yes/no"),
    "error": ("the speed study's error of the model (its inference metric)", "as the model's metric"),
}
FAMILIES = {"train": "on training-family trajectories", "test": "on unseen (test-family) trajectories",
            "train_x2": "on the training family played twice as fast"}
AGGREGATES = {"median": "median over initial states", "finite": "mean over the finite (not diverged) rollouts",
              "q25": "25th percentile over initial states", "q75": "75th percentile over initial states"}
SETS = {"heldout": "on the fit's held-out rows", "test": "on the fit's test rows"}


def define(name: str) -> tuple[str, str] | None:
    """(meaning, unit) of a metric name, or None where neither the table nor a naming rule knows it."""
    name = str(name).strip()
    if name in METRICS:
        return METRICS[name]
    rules = (
        (r"null_(.+)", lambda m, d: (f"the null predictor's {m[1]} (the better of predicting zero and the mean)", d[1])),
        (r"matched_(.+)", lambda m, d: (f"{d[0]}, read at matched accuracy", d[1])),
        (r"chaos_floor_(.+)", lambda m, d: (f"{d[0]}, of the truth from starts moved by a tiny perturbation "
                                            f"(what chaos allows)", d[1])),
        (r"(.+)_joint(\d+)", lambda m, d: (f"{d[0]}, joint {m[2]}", d[1])),
        (r"(.+)_(train_x2|train|test)", lambda m, d: (f"{d[0]} {FAMILIES[m[2]]}", d[1])),
        (r"(.+)_(median|finite|q25|q75)", lambda m, d: (f"{d[0]}; {AGGREGATES[m[2]]}", d[1])),
        (r"(heldout|test)_(.+)", lambda m, d: (f"{d[0]} {SETS[m[1]]}", d[1])),
    )
    for pattern, build in rules:
        m = re.fullmatch(pattern, name)
        if m:
            inner = m[2] if pattern.startswith("(heldout") else m[1]
            d = define(inner)
            if d is not None:
                return build(m, d)
    return None


def unit(name: str) -> str:
    d = define(name)
    return d[1] if d else ""


IDENTIFIER = re.compile(r"^[a-z][a-z0-9]*(_[a-z0-9]+)+$")


def metric_names(sections: list[Section]) -> list[str]:
    """The snake_case column headers of every table and the metrics named in scorecard "key number" cells, in
    order of appearance: the names the glossary must define."""
    names: dict[str, None] = {}
    for s in sections:
        for b in s.blocks:
            if not isinstance(b, Table):
                continue
            for c in b.df.columns:
                if IDENTIFIER.match(str(c)):
                    names.setdefault(str(c), None)
            if "key number" in b.df.columns:   # "<model> <metric> (<unit>): ..."
                for text in b.df["key number"].astype(str):
                    m = re.match(r"\S+ (\S+)", text)
                    if m and IDENTIFIER.match(m[1]):
                        names.setdefault(m[1], None)
    return list(names)


def _metrics_table(names: list[str]) -> pd.DataFrame:
    rows = []
    for name in names:
        d = define(name)
        rows.append({"metric": name, "meaning": d[0] if d else "recorded by the units; not defined in the suite's "
                                                                "glossary (reports/glossary.py)",
                     "unit": d[1] if d else "–"})
    return pd.DataFrame(rows)


def glossary_section(sections: list[Section]) -> Section:
    """The terms, then each metric name the tables of ``sections`` show with its meaning and unit."""
    s = Section("Glossary")
    s.add(Para("The words the scorecard uses, then every metric name the tables show."))
    s.add(Bullets([f"{term}: {text}." for term, text in TERMS]))
    names = metric_names(sections)
    if names:
        s.add(Table("Metric names", _metrics_table(names), ["reports/glossary.py", "docs/RESULTS.md"]))
    return s


def more_metric_names(sections: list[Section], defined: list[Section]) -> list[Section]:
    """The metric names the tables of ``sections`` show that those of ``defined`` (the glossary's) do not, each
    with its meaning and unit: the glossary's continuation for the appendix ([] when there are none)."""
    known = set(metric_names(defined))
    names = [n for n in metric_names(sections) if n not in known]
    if not names:
        return []
    s = Section("Glossary: the appendix's metric names")
    s.add(Para("Every metric name the appendix's tables show that the Glossary (after the scorecard) does not."))
    return [s.add(Table("Metric names in the appendix", _metrics_table(names),
                        ["reports/glossary.py", "docs/RESULTS.md"]))]
