"""Training to a target: samples the double-pendulum LNN needs to reach held-out L1 thresholds.

The paper prints 7.3e-2 for its double-pendulum LNN. That is a late-epoch training loss, not a held-out
value (the original code's held-out L1 is 6.9e-2, reference §7); the thresholds below are held-out L1,
so 0.073 here is a held-out target a little looser than the like-for-like 0.069. The original code consumed
about 3e8 samples (300 epochs x 2000 batches x 512). The issue asks for a protocol reaching it with at
most a tenth of that (3e7). On 2 CPU cores the LNN trains at a few thousand samples per second, so this
study runs every protocol for the same `sizes.target_budget` samples and reports how far each got:

  "original_scaled": the code's protocol (`claims.double_pendulum.PROTOCOLS["paper"]`: batch 512, Adam,
      cosine one-cycle with peak 1e-3, l2 1e-6/512, per-sample L1, states resampled), its one-cycle
      stretched over the budget instead of 3e8 samples;
  "variant": batch 32, the code's one-cycle cosine at peak 1e-3 over the budget, the gradient-spike guard
      (`replication.training.spike_guard`: clip the gradient norm at 100, skip a step whose norm is >= 10 x the
      median of the last 200), and the MLP's velocity inputs scaled by 0.3 (`ModelSpec.input_scale`;
      velocities are U[-10, 10], angles wrapped to [-pi, pi)). How it was chosen, and every protocol
      tried on the way with its held-out L1, is in `train_target_trials.md` beside this file. In short:
      without the guard every run stalled at L1 16-20 or diverged on gradient spikes from near-singular
      learned Hessians; with it the LNN gets below 10, but its H is still not the mass matrix.
  "restarts": the variant with restarts over initialisations: RESTART_SEEDS inits are each trained for
      scouting.SCOUT_SAMPLES samples (at most half the budget over all of them; a one-cycle over the scout), the one
      with the lowest training loss (its last 5 % of batches; the held-out set plays no part) continues
      for the rest of the budget with a new one-cycle and fresh Adam state. The budget counts every scout's
      samples. Why: which init finds a near-physical Lagrangian is luck (after 5e5 samples, 3 of 8 seeds at
      3x64, 2 of 8 and 3 of 8 at 3x128), a run that found one trains on without gradient spikes, and its
      training loss tells which it is (`train_target_trials.md`, section 5).
  "restarts_fast": restarts, the scouts alike, the continuation at batch 256 and peak 2e-3 (the full
      profile's double-pendulum protocol): about three times the samples per second of batch 32.
  "restarts_halved": restarts_fast with successive halving (`Scouting.keep`, as the quick claims
      scout): HALVED_SEEDS inits run half their scout, the HALVED_KEEP lowest by training loss go on to its
      end, the lowest of those continues as in restarts_fast. More inits for a quarter more scout samples:
      with 8 whole scouts a run finds no near-physical Lagrangian often enough to matter (all 8 missed,
      tails 10-18, in a 2-thread run at seed 0; `train_target_trials.md` section 9).
The five use the claim's LNN spec (softplus, empirical init, angle wrapping) at `sizes.target_hidden`. Beside
them, for reference (not a target row):
  "baseline_reference": the claim's plain MLP baseline (ReLU, Glorot init, q'' straight out) on the
      variant's protocol and inputs: what the same samples buy when no Euler-Lagrange solve is learned.

Why the LNN stalls, measured: `hessian_rel_err` is the median over the held-out states of
||H - c H_true||_F / ||c H_true||_F, H the final model's velocity Hessian d2L/dqdot2, H_true the system's
(the mass matrix), c one least-squares scale for the whole set (L is defined up to a constant factor and
a total time derivative; neither changes c H_true). Near 0: the LNN found the true Lagrangian up to those
symmetries; order 1: its accelerations come from some other Lagrangian (the inverse problem admits many),
whose Euler-Lagrange equations only partly fit. NaN for the baseline.

The training loop is `target_loop.run_protocol` (the suite's optimiser step, batches, schedule and loss,
plus a held-out evaluation every `budget / N_EVALS` samples). Held-out L1: `objective.loss_value`
("l1": per-sample sum of |q''_pred - q''_true| over components, mean over samples) on
`data.heldout(protocol, heldout_seed)` (`sizes` or --heldout-states decides its size; heldout_seed the
split's, `replication.run.splits`: the development draw unless `lagbench train-target --split test`). The
held-out L1 and `hessian_rel_err` only report: training never reads the held-out draw.

`train_target_rows(sizes, progress) -> (rows, log)` (the bench's stage, at the preset's budget and widths);
`study(budget, hidden, n_heldout, names, progress, on_eval, seed, on_model, heldout_seed)` the same for any
budget (`lagbench train-target`; seed: one init seed, or {protocol: init seed}):
  rows {protocol, model, description, hidden, budget, threshold, samples_to_reach, wall_s_to_reach, reached,
        best_l1, final_l1, seed, hessian_rel_err, skipped_steps, samples_per_s, wall_s, extrapolated_samples,
        extrapolation}:
        samples_to_reach is the first evaluation at or below the threshold (NaN: "not reached within
        budget <N>" in `reached`), wall_s_to_reach the training steps' wall seconds up to it (as wall_s:
        compiling and the held-out evaluations excluded); seed: the init seed of the final model (restarts:
        the one chosen);
        extrapolated_samples is NOT measured: a power law L1 = a * samples^b fitted to the best-so-far
        held-out L1 over the last half of the evaluations, solved for the threshold (`_extrapolate`; NaN:
        flat, inf: beyond 1000 x 3e8 samples);
  log {protocol, phase, seed, step, samples, lr, train_loss, heldout_l1, wall_s, skipped_steps, scout_loss} (phase: train,
  or scout / continue for restarts; step and samples count from the protocol's start; scout_loss: on a
  scout's row, the training loss its choice was made on, else empty; wall_s: training steps
  after the first, compiling one; held-out evaluations excluded; skipped_steps: steps the spike guard has
  skipped so far, 0 when it is off).
"""
from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np

from lagbench import systems
from lagbench.models import ModelSpec
from lagbench.replication.claims.double_pendulum import MODELS, PLAIN_QUICK, PROTOCOLS
from lagbench.replication.training import data as datamod
from lagbench.replication.training import scouting
from lagbench.replication.training.data import HELDOUT_SEED
from lagbench.replication.training.protocol import Guard, Scouting
from lagbench.replication.training.schedules import OneCycle
from lagbench.speedstudy.target_loop import N_EVALS, run_protocol

PAPER_L1, ORIGINAL_SAMPLES = 7.3e-2, 3e8  # the paper's number (a training loss; held-out 6.9e-2); the code's samples
CODE_HELDOUT_L1 = 6.9e-2                  # the original code's held-out L1 (reference §7): the like-for-like target
THRESHOLDS = (10.0, 3.0, 1.0, 0.3, PAPER_L1, CODE_HELDOUT_L1)
TARGET_SAMPLES = ORIGINAL_SAMPLES / 10     # the target: at most a tenth
EXTRAPOLATION_CAP = 1e3 * ORIGINAL_SAMPLES
HELDOUT = {"tiny": 256, "quick": 4096, "full": 20_000}


VARIANT_BATCH, VARIANT_LR, VELOCITY_SCALE = 32, 1e-3, 0.3
GRAD_CLIP, SPIKE_SKIP = 100.0, 10.0
RESTART_SEEDS = 8  # "restarts": inits scouted (each for SCOUT_SAMPLES samples, at most half the budget in all)
SCOUT_SAMPLES = 500_000
HALVED_SEEDS, HALVED_KEEP = 16, 4   # "restarts_halved": inits scouted, and kept past half their scout
FAST_BATCH, FAST_LR = 256, 2e-3   # "restarts_fast": the continuation's batch and peak rate


class Entry(NamedTuple):
    """One protocol of the study: the Protocol (its steps: the whole budget), a description, ModelSpec
    overrides, and the model label in `claims.double_pendulum.MODELS`; restarts are the protocol's `scouting`."""
    protocol: object
    description: str
    overrides: dict
    label: str


def protocols(budget: int, n_heldout: int) -> dict[str, Entry]:
    """{name: Entry} for a budget in samples."""
    paper = PROTOCOLS["paper"]
    pool = min(paper.data.n_train, max(paper.batch, budget // paper.batch * paper.batch))
    orig = paper.replace(steps=max(budget // paper.batch, 2), data=paper.data.replace(n_train=pool, n_heldout=n_heldout),
                         log_every=10**9)
    steps = max(budget // VARIANT_BATCH, 3)
    var = PLAIN_QUICK.replace(steps=steps, batch=VARIANT_BATCH,
                              data=PLAIN_QUICK.data.replace(n_train=VARIANT_BATCH * 1000, n_heldout=n_heldout),
                              schedule=OneCycle(lr=VARIANT_LR), guard=Guard(clip=GRAD_CLIP, skip=SPIKE_SKIP),
                              log_every=10**9)
    scale = {"input_scale": (1.0, 1.0, VELOCITY_SCALE, VELOCITY_SCALE)}
    var_text = (f"batch {var.batch}, one-cycle peak {var.schedule.lr:g} over {var.steps} steps, l2 {var.l2:.3g}, "
                f"gradient clip {GRAD_CLIP:g}, skip at "
                f"{SPIKE_SKIP:g} x median gradient norm; MLP input velocities scaled by {VELOCITY_SCALE:g}")
    # scouts: SCOUT_SAMPLES each, at most half the budget over all of them; the continuation the rest
    scout = max(min(SCOUT_SAMPLES, budget // (2 * RESTART_SEEDS)) // var.batch, 3)
    rest = max(var.steps - RESTART_SEEDS * scout, 1)
    restarts = var.replace(scouting=Scouting(count=RESTART_SEEDS, steps=scout, batch=var.batch, schedule=var.schedule),
                           steps=rest)
    restarts_text = (f"{RESTART_SEEDS} seeds scouted for {scout} steps each (one-cycle over the scout), the one with "
                     f"the lowest training loss (mean of its last 5 % of batches) continued for {rest} steps "
                     f"(a new one-cycle, fresh Adam state); otherwise the variant: batch {var.batch}, peak "
                     f"{var.schedule.lr:g}, clip {GRAD_CLIP:g}, skip at {SPIKE_SKIP:g} x median, velocity scale "
                     f"{VELOCITY_SCALE:g}. Samples count every scout")
    # restarts_fast: the scouts as in restarts, the continuation at a wider batch and a higher peak, same budget
    fast_rest = max((budget - RESTART_SEEDS * scout * var.batch) // FAST_BATCH, 1)
    fast = restarts.replace(steps=fast_rest, batch=FAST_BATCH, **{"data.n_train": FAST_BATCH * 1000, "schedule.lr": FAST_LR})
    fast_text = (f"{RESTART_SEEDS} seeds scouted for {scout} steps each at batch {var.batch}, peak {var.schedule.lr:g}, as "
                 f"restarts; the chosen one continued for {fast_rest} steps at batch {FAST_BATCH}, peak {FAST_LR:g} "
                 f"(a new one-cycle, fresh Adam state). Samples count every scout")
    # restarts_halved: restarts_fast's scouts and continuation, HALVED_SEEDS scouts halved to HALVED_KEEP (at
    # 4e7 samples the full profile's double-pendulum protocol, `claims.double_pendulum.PROTOCOLS["full"]`)
    halved = fast.replace(**{"scouting.count": HALVED_SEEDS, "scouting.keep": HALVED_KEEP})
    halved = halved.replace(steps=max((budget - scouting.scouting_samples(halved)) // FAST_BATCH, 1))
    halved_text = (f"{HALVED_SEEDS} seeds scouted at batch {var.batch}, peak {var.schedule.lr:g}, for {scout} steps; at step "
                   f"{scouting.cut_step(halved)} the {HALVED_KEEP} lowest by training loss go on to the end, the lowest "
                   f"of those continued for {halved.steps} steps at batch {FAST_BATCH}, peak {FAST_LR:g} (a new "
                   f"one-cycle, fresh Adam state). Samples count every scout")
    return {"original_scaled": Entry(orig, f"code protocol: batch {orig.batch}, one-cycle peak {orig.schedule.lr:g} over "
                                           f"{orig.steps} steps, l2 {orig.l2:.3g}", {}, "lnn"),
            "variant": Entry(var, var_text, scale, "lnn"),
            "restarts": Entry(restarts, restarts_text, scale, "lnn"),
            "restarts_fast": Entry(fast, fast_text, scale, "lnn"),
            "restarts_halved": Entry(halved, halved_text, scale, "lnn"),
            "baseline_reference": Entry(var, f"the MLP baseline on the variant's protocol: {var_text}", scale,
                                        "baseline")}


def hessian_rel_err(model, spec, protocol, heldout_seed: int = HELDOUT_SEED) -> float:
    """Median over the held-out states (the draw of generator heldout_seed) of ||H - c H_true||_F /
    ||c H_true||_F (module doc); NaN for models without a velocity Hessian."""
    if spec.kind != "lnn":
        return float("nan")
    data = datamod.heldout(protocol, heldout_seed)
    q, qd = (jnp.asarray(data[k], protocol.dtype) for k in ("q", "qdot"))
    h = np.asarray(model.velocity_hessian(q, qd), float)
    h_true = np.asarray(systems.get("double_pendulum", **dict(protocol.data.system_params))
                        .velocity_hessian(data["q"], data["qdot"]), float)
    c = float(np.sum(h * h_true) / np.sum(h_true * h_true))
    if not (np.isfinite(c) and c != 0.0):
        return float("nan")
    return float(np.median(np.linalg.norm(h - c * h_true, axis=(-2, -1))
                           / np.linalg.norm(c * h_true, axis=(-2, -1))))


def _extrapolate(samples, l1, threshold) -> float:
    """NOT a measurement: samples at which a power law a * samples^b, fitted (log-log least squares) to the
    last half of the best-so-far held-out L1 (what checkpointing the best model keeps), reaches threshold;
    NaN where that curve is flat (b > -1e-3), inf beyond EXTRAPOLATION_CAP (the measured trend does not
    get there within a thousand times the original code's budget)."""
    s, v = np.asarray(samples, float), np.asarray(l1, float)
    keep = (s > 0) & np.isfinite(v) & (v > 0)
    s, v = s[keep], np.minimum.accumulate(v[keep])
    s, v = s[len(s) // 2:], v[len(v) // 2:]
    if len(s) < 3:
        return np.nan
    b, a = np.polyfit(np.log(s), np.log(v), 1)
    if not b < -1e-3:
        return np.nan
    if v[-1] <= threshold:
        return np.nan  # reached: nothing to extrapolate
    n = np.exp(min((np.log(threshold) - a) / b, 700.0))
    return float(n) if n <= EXTRAPOLATION_CAP else np.inf


def summarise(name, description, spec, protocol, log, h_err=float("nan")) -> list[dict]:
    s = np.array([r["samples"] for r in log], float)
    v = np.array([r["heldout_l1"] for r in log], float)
    wall = log[-1]["wall_s"]
    rows = []
    for thr in THRESHOLDS:
        hit = np.nonzero(v <= thr)[0]
        budget = scouting.budget_samples(protocol)
        rows.append({"protocol": name, "model": spec.kind, "description": description,
                     "hidden": "x".join(map(str, spec.hidden)), "budget": budget, "threshold": thr,
                     "samples_to_reach": float(s[hit[0]]) if hit.size else np.nan,
                     "wall_s_to_reach": float(log[hit[0]]["wall_s"]) if hit.size else np.nan,
                     "reached": "yes" if hit.size else f"not reached within budget {budget}",
                     "best_l1": float(np.nanmin(v)), "final_l1": float(v[-1]), "seed": int(log[-1]["seed"]),
                     "hessian_rel_err": h_err,
                     "skipped_steps": int(log[-1]["skipped_steps"]),
                     "samples_per_s": (s[-1] - protocol.batch) / wall if wall > 0 else np.nan, "wall_s": wall,
                     "extrapolated_samples": _extrapolate(s, v, thr),
                     "extrapolation": "EXTRAPOLATED, not measured: power law fitted to the last half of the "
                                      "best-so-far held-out L1"})
    return rows


def train_target_rows(sizes, progress=None) -> tuple[list[dict], list[dict]]:
    if not sizes.target_budget:
        return [], []
    return study(sizes.target_budget, sizes.target_hidden, HELDOUT.get(sizes.name, 4096), progress=progress)


def study(budget: int, hidden, n_heldout: int, names=None, progress=None, on_eval=None, seed=0,
          on_model=None, heldout_seed: int = HELDOUT_SEED):
    """(rows, log) of the protocols `names` (default all of `protocols`) at `budget` samples and MLP widths
    `hidden`; `on_eval(log so far)` after every held-out evaluation (the CLI writes the log there); seed:
    the init seed (restarts: the first of those scouted), one for every protocol or a {name: seed} dict;
    `on_model(name, spec, model)` with each protocol's final model (the CLI saves it); heldout_seed: the
    generator seed of the held-out draw every evaluation reads."""
    if not budget >= 1:
        raise ValueError(f"the train-target budget must be at least 1 sample, got {budget!r}")
    table = protocols(int(budget), n_heldout)
    unknown = sorted(set(names or ()) - set(table))
    if unknown:
        raise ValueError(f"unknown train-target protocol(s) {', '.join(unknown)}; valid: {', '.join(table)}")
    rows, logs = [], []
    for name in names or table:
        proto, desc, over, label = table[name]
        entry = next(m for m in MODELS if m.label == label)
        spec = ModelSpec(dof=2, hidden=tuple(hidden), dtype=proto.dtype, **{**entry.spec, **over})
        if progress:
            progress.set_postfix_str(f"train to target: {name}")
        each = (lambda lg, done=list(logs): on_eval(done + lg)) if on_eval else None
        init = seed[name] if isinstance(seed, dict) else seed
        log, model = run_protocol(name, spec, proto, seed=init, on_eval=each, heldout_seed=heldout_seed)
        logs += log
        if on_model:
            on_model(name, spec, model)
        rows += summarise(name, desc, spec, proto, log, hessian_rel_err(model, spec, proto, heldout_seed))
        if progress:
            progress.update(1)
    return rows, logs


def n_evaluations(entry: Entry) -> int:
    """Held-out evaluations after step 0 of one protocol (the CLI's progress bar)."""
    return N_EVALS + (entry.protocol.scouting.count if entry.protocol.scouting else 0)


def n_cases(sizes) -> int:
    return len(protocols(1000, 1)) if sizes.target_budget else 0
