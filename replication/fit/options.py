"""`lagbench fit`'s options, written once: the keyword of `fit`, the command-line flag, the default, the
help, how the flag's text is read and what a valid value is.

`OPTIONS`: the records, in the order of the command's help (their parsers and validators:
`replication.fit.option_values`). `resolve(given) -> Options` (attribute access):
every option's value, the default where not given; a TypeError names a keyword that is no option.
`check(values)`: a ValueError naming the first invalid option of `values` (any subset, by keyword) and
what it accepts. `add_arguments(parser)`: the flags of `lagbench fit`. `from_args(args) -> dict`: the
keywords of `fit` from parsed flags (a flag's text read by the option's `parse`).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

from lagbench.models import ACTIVATIONS
from lagbench.models.spec import CAPABILITIES
from lagbench.replication.fit.energy_trend import MODES as DISSIPATION_MODES
from lagbench.replication.fit.even_velocity import MODES as EVEN_VELOCITY_MODES
from lagbench.replication.fit.kind_defaults import HELDOUT_CHECKS, MIN_IMPROVEMENT
from lagbench.replication.fit.loss_target import MODES as LOSS_TARGETS
from lagbench.replication.fit.option_values import (
    count,
    one_of,
    periodic_value,
    scale,
    valid_periodic,
    widths,
)
from lagbench.replication.fit.rows import HELDOUT, SPLITS
from lagbench.replication.fit.time_base import TIME_UNITS
from lagbench.replication.fit.trajectories import AUTO, GAPS, MAX_GAP, POLYORDER, window_value
from lagbench.replication.fit.windows import FRAMES, SUBSTEPS
from lagbench.replication.renamed import renamed
from lagbench.replication.training.protocol_parts import TRAJECTORY_SCALES
from lagbench.validate import is_real

MODELS = ("lnn", "hnn", "delan", "baseline")
FRAMEWORKS = ("jax", "torch")
LOSSES = ("l1", "mse")
SCHEDULES = ("onecycle", "constant")


class _ByKind:
    """The default of an option that the model kind sets (`replication.fit.kind_defaults`)."""

    def __repr__(self):
        return "the model kind's default"


BY_KIND = _ByKind()
KIND = " (default: the model kind's, from the suite's protocols; see docs/fit.md)"
HORIZON_HELP = ("seconds from each trajectory's start that the rollouts cover (longer trajectories are rolled "
                "out and scored to there)")


@dataclass(frozen=True)
class Option:
    name: str                      # fit()'s keyword
    default: object
    help: str
    valid: Callable | None = None  # value -> bool (None: any value)
    expected: str = ""             # what `valid` accepts, for the error
    flag: str = ""                 # the command-line spelling (default: --name with dashes)
    parse: Callable | None = None  # the flag's text -> value (None: argparse's `type`)
    kind: type | None = None       # argparse `type` where parse is None
    text: str | None = None        # the flag's default text where parse is used
    switch: bool = False           # a flag without a value (store_true)
    required: bool = False         # on the command line
    old: str = ""                  # an earlier spelling, still read with a deprecation notice
    const: str | None = None       # the value of the flag given without one (argparse nargs="?")

    @property
    def cli(self) -> str:
        return self.flag or "--" + self.name.replace("_", "-")


OPTIONS = (
    Option("model", "lnn", "lnn | hnn | delan | baseline (lnn and hnn refuse data with tau)", one_of(MODELS),
           f"one of {', '.join(MODELS)}", required=True),
    Option("test", None, "a file of the same format evaluated as a whole after training (rollouts from each "
           "trajectory's first state)"),
    Option("split", None, "how rows are held out: whole trajectories, random rows, or none (default: "
           "by-trajectory for a trajectory file, random for a state file)", lambda v: v is None or v in SPLITS,
           f"one of {', '.join(SPLITS)}", flag="--holdout", old="--split"),
    Option("heldout", HELDOUT, "fraction held out (of trajectories or rows)", kind=float, flag="--holdout-fraction",
           old="--heldout"),
    Option("gaps", "interpolate", f"dropped frames in a trajectory file: interpolate (up to {MAX_GAP} in a row, cubic "
           "spline; the filled rows are not trained on), split (each piece its own trajectory) or refuse",
           one_of(GAPS), f"one of {', '.join(GAPS)}"),
    Option("time_unit", "s", "the unit of a trajectory file's t column: s (seconds) or ms (milliseconds, read as "
           "t / 1000); with --system, a time step longer than the system's time scale is refused, naming the unit "
           "it looks like", one_of(TIME_UNITS), f"one of {', '.join(TIME_UNITS)}"),
    Option("window", AUTO, "Savitzky-Golay window for the derivatives a trajectory file lacks: auto (chosen from the "
           "recording's own noise and motion, for the q-double-dot the loss trains on; docs/fit.md) or an odd number "
           "of samples", parse=window_value, text=AUTO),
    Option("polyorder", POLYORDER, "Savitzky-Golay polynomial degree (>= 2)", kind=int),
    Option("framework", "jax", "jax | torch", one_of(FRAMEWORKS), f"one of {', '.join(FRAMEWORKS)}"),
    Option("steps", BY_KIND, "optimiser steps, >= 1" + KIND, count(1), "an integer >= 1", kind=int),
    Option("batch", BY_KIND, "batch size, >= 1; at most the training rows" + KIND, count(1), "an integer >= 1", kind=int),
    Option("hidden", BY_KIND, "comma-separated MLP widths" + KIND,
           lambda v: len(v) > 0 and all(count(1)(h) for h in v), "comma-separated layer widths >= 1 such as 128,128",
           parse=widths),
    Option("activation", BY_KIND, "softplus | relu | relu2 | relu3 | tanh | sigmoid" + KIND, one_of(ACTIVATIONS),
           f"one of {', '.join(ACTIVATIONS)}"),
    Option("lr", BY_KIND, "peak learning rate, > 0" + KIND, lambda v: is_real(v) and v > 0, "a finite number > 0",
           kind=float),
    Option("schedule", BY_KIND, "onecycle | constant" + KIND, one_of(SCHEDULES), f"one of {', '.join(SCHEDULES)}"),
    Option("lr_start", BY_KIND, "one-cycle: the phase the cycle starts at, in [0, 1) (0.5 is the peak; the rate "
           "there is --lr x (1 - cos(2 pi phase)) / 2)" + KIND, lambda v: is_real(v) and 0 <= v < 1, "a number in [0, 1)",
           kind=float),
    Option("lr_min_ratio", BY_KIND, "one-cycle: final rate as a fraction of --lr" + KIND,
           lambda v: is_real(v) and 0 < v <= 1, "a fraction in (0, 1]", flag="--lr-final", kind=float),
    Option("weight_decay", BY_KIND, "L2 penalty: coefficient of sum(theta^2) added to the loss" + KIND,
           lambda v: is_real(v) and v >= 0, "a finite number >= 0", kind=float),
    Option("loss", BY_KIND, "l1 | mse (per sample summed over components, mean over the batch)" + KIND,
           one_of(LOSSES), f"one of {', '.join(LOSSES)}"),
    Option("loss_target", AUTO, "what the loss compares: auto (filtered for DeLaN on a trajectory file whose "
           "q-double-dot is estimated from q, by a registered study; acceleration otherwise), acceleration (the "
           "model's q-double-dot with the estimated one, row by row), trajectory (a trajectory file only: the model's motion integrated by RK4 from "
           "each recorded frame over the next --horizon-frames frames, with the recorded positions; "
           "docs/lab/trajectory_loss.md) or filtered (a trajectory file whose derivatives are estimated, the "
           "acceleration task: the estimate with the model's q-double-dot at the frames the filter's window spans, "
           "smoothed as the filter smooths it, so the model does not learn the filter's bias; "
           "docs/fit.md); the held-out rows are scored by the q-double-dot error either way",
           one_of(LOSS_TARGETS), f"one of {', '.join(LOSS_TARGETS)}"),
    Option("horizon_frames", FRAMES, "trajectory loss: the frames each window integrates over, >= 1", count(1),
           "an integer >= 1", kind=int),
    Option("horizon_substeps", SUBSTEPS, "trajectory loss: RK4 steps per frame, >= 1", count(1), "an integer >= 1",
           kind=int),
    Option("horizon_scale", "acceleration", "trajectory loss: acceleration (each window's position errors divided by "
           "those a constant q-double-dot error of 1 gives over it: the loss in q-double-dot units, as the "
           "acceleration loss) or none (positions as recorded)", one_of(TRAJECTORY_SCALES),
           f"one of {', '.join(TRAJECTORY_SCALES)}"),
    Option("patience", BY_KIND, f"early stop: the held-out rows are evaluated {HELDOUT_CHECKS} times over --steps, and "
           f"the training stops after this many evaluations in a row that do not improve on the best so far by "
           f"{MIN_IMPROVEMENT:g} of it, then anneals its rate over the steps the patience spans, keeping the last "
           f"step's parameters (0: off; needs held-out rows)" + KIND,
           count(0), "an integer >= 0", kind=int),
    Option("seed", 0, "initialisation and batch-order seed, >= 0", count(0), "an integer >= 0", kind=int),
    Option("restarts", BY_KIND, "restarts over initialisations, as the claims train LNNs off their qddot ~ 0 plateau: "
           "this many inits (>= 2; 0: none) train side by side for --restart-steps steps, the lowest training loss "
           "goes on for --steps" + KIND, lambda v: v is None or v == 0 or count(2)(v), "0 or an integer >= 2",
           kind=int),
    Option("restart_steps", None, "steps of each restart (default: --steps x the kind's ratio, or / 8)",
           lambda v: v is None or count(1)(v), "an integer >= 1", kind=int),
    Option("restart_keep", BY_KIND, "successive halving: at half their steps only this many restarts (the lowest "
           "training losses) go on" + KIND, lambda v: v is None or count(1)(v), "an integer >= 1", kind=int),
    Option("restart_fallback", BY_KIND, "where the chosen restart's main training ends above that restart's "
           "training loss (it lost what the restart found), the next restart's goes on instead, up to this many more "
           "(0: none)" + KIND, lambda v: v is None or count(0)(v), "an integer >= 0", kind=int),
    Option("restart_batch", BY_KIND, "batch size of the restarts" + KIND + "; --batch where the kind has none",
           lambda v: v is None or count(1)(v), "an integer >= 1", kind=int),
    Option("restart_lr", None, "peak rate of the restarts' one-cycle (default: --lr x the kind's ratio, or --lr)",
           lambda v: v is None or (is_real(v) and v > 0), "a finite number > 0", kind=float),
    Option("guard_clip", BY_KIND, "gradient-spike guard: clip the gradient's norm to this (0: no clip)" + KIND,
           lambda v: v is None or (is_real(v) and v >= 0), "a number >= 0", kind=float),
    Option("guard_skip", BY_KIND, "gradient-spike guard: skip a step whose gradient norm is at least this many times "
           "the recent median (0: no skip)" + KIND, lambda v: v is None or (is_real(v) and v >= 0), "a number >= 0",
           kind=float),
    Option("delan_eps", 0.01, "DeLaN: epsilon of M = L L^T + eps I", lambda v: is_real(v) and v >= 0,
           "a finite number >= 0", kind=float),
    Option("delan_offset", 2.0, "DeLaN: diag(L) = softplus(raw + offset)", is_real, "a finite number", kind=float),
    Option("angle_wrap", False, "input feature: wrap q to [-pi, pi) before the MLP", switch=True),
    Option("periodic", AUTO, "input feature: coordinates fed to the network as cos and sin (angles recorded "
           "unwrapped): auto (with --system and without --angle-wrap, those in which the system's Lagrangian is "
           "2 pi-periodic; otherwise none), none, or indices such as 0,1", valid_periodic,
           "auto, none or comma-separated coordinate indices >= 0 such as 0,1", text=AUTO, parse=periodic_value),
    Option("dissipation", AUTO, "lnn, hnn, delan: learn a Rayleigh dissipation D = 1/2 sum b_k qdot_k^2 (b_k >= 0: "
           "viscous friction per coordinate) beside the Lagrangian or Hamiltonian, for data that lose energy: auto "
           "(on where the training trajectories lose energy by the true energy of --system or --energy, off otherwise "
           "and for the baseline; docs/fit.md), on (also --dissipation alone) or off",
           lambda v: v in DISSIPATION_MODES or isinstance(v, bool), f"one of {', '.join(DISSIPATION_MODES)}",
           text=AUTO, parse=str, const="on"),
    Option("even_velocity", AUTO, "lnn: a Lagrangian even in qdot, L = (N(q, qdot) + N(q, -qdot)) / 2 with N the "
           "network (the time-reversal symmetry of a mechanical system without magnetic forces: the dissipation is "
           "then the model's only force odd in qdot; twice the network's work a step): auto (on for an LNN that "
           "learns a dissipation on a trajectory file whose estimated position noise is at or above the budget's "
           "switch, with half the steps there; off otherwise; docs/fit.md), on (also --even-velocity alone) or off",
           lambda v: v in EVEN_VELOCITY_MODES or isinstance(v, bool), f"one of {', '.join(EVEN_VELOCITY_MODES)}",
           text=AUTO, parse=str, const="on"),
    Option("input_scale", BY_KIND, "input feature: multipliers of the MLP inputs [q (cos, sin for --periodic), "
           "qdot(, qddot)]: none, auto (1 / standard deviation over the training rows) or numbers such as 1,1,0.3,0.3"
           + KIND,
           lambda v: v in (None, "auto") or (isinstance(v, tuple) and all(is_real(x) and x > 0 for x in v)),
           "none, auto or positive numbers such as 1,1,0.3,0.3", parse=scale),
    Option("system", None, "a system name (see `lagbench list`) whose true energy (and DeLaN terms) the "
           "evaluation compares against (default: none)"),
    Option("energy", None, "your energy function E(q, qdot) as module:function (importable from here; (N, d) "
           "arrays to (N,)), compared along the rollouts in place of --system's"),
    Option("substeps", 2, "RK4 steps per sample interval in the rollouts", count(1), "an integer >= 1", kind=int),
    Option("horizon", None, HORIZON_HELP + " (default: whole trajectories)", lambda v: v is None or (is_real(v) and v > 0),
           "a number of seconds > 0", kind=float),
)
BY_NAME = {o.name: o for o in OPTIONS}


def resolve(given: dict) -> SimpleNamespace:
    unknown = sorted(set(given) - set(BY_NAME))
    if unknown:
        raise TypeError(f"fit() got unknown options {', '.join(unknown)}; valid: {', '.join(BY_NAME)}")
    values = {o.name: given.get(o.name, o.default) for o in OPTIONS}
    if isinstance(values["hidden"], list):
        values["hidden"] = tuple(values["hidden"])
    if isinstance(values["input_scale"], list):
        values["input_scale"] = tuple(values["input_scale"])
    for name in ("dissipation", "even_velocity"):   # fit(dissipation=True) as --dissipation on
        if isinstance(values[name], bool):
            values[name] = "on" if values[name] else "off"
    return SimpleNamespace(**values)


def check(values: dict) -> None:
    """Options left at BY_KIND are not checked here (`kind_defaults.fill` fills and checks them)."""
    for o in OPTIONS:
        if o.name in values and values[o.name] is not BY_KIND and o.valid is not None and not o.valid(values[o.name]):
            v = values[o.name]
            shown = ",".join(map(str, v)) if o.name == "hidden" and isinstance(v, tuple) else v
            raise ValueError(f"{o.cli}: {shown!r} is not valid; expected {o.expected}")
    keep, restarts = values.get("restart_keep"), values.get("restarts")
    if BY_KIND not in (keep, restarts) and keep is not None and (not restarts or keep >= restarts):
        raise ValueError(f"--restart-keep: {keep!r} needs --restarts above it (the restarts that go on after the "
                         f"first half)")
    fallback = values.get("restart_fallback")
    if BY_KIND not in (keep, restarts, fallback) and fallback and (not restarts or fallback >= (keep or restarts)):
        raise ValueError(f"--restart-fallback: {fallback!r} needs more restarts that reach the end "
                         f"({keep or restarts or 0} do): each fallback goes on from another of them")
    if values.get("dissipation") in ("on", True) and values.get("model") in MODELS and not CAPABILITIES[values["model"]].dissipation:
        raise ValueError("--dissipation: for --model lnn, hnn or delan (a structured model with a Rayleigh "
                         "function); the baseline's q-double-dot is free-form already")
    if values.get("even_velocity") in ("on", True) and values.get("model") in MODELS and values["model"] != "lnn":
        raise ValueError("--even-velocity: for --model lnn (a network of q-dot whose Lagrangian it makes even)")
    system = values.get("system")
    if system is not None:
        from lagbench import systems

        if system not in systems.names():
            raise ValueError(f"--system: unknown {system!r}; valid: {', '.join(systems.names())}")


def add_arguments(parser) -> None:
    import argparse

    for o in OPTIONS:
        if o.old:   # `run --split` is the development or test split and `train-target --heldout` a count of states
            parser.add_argument(o.old, dest="old_" + o.name, type=o.kind, choices=SPLITS if o.name == "split" else None,
                                help=argparse.SUPPRESS)
        if o.switch:
            parser.add_argument(o.cli, action="store_true", help=o.help)
        elif o.const is not None:
            parser.add_argument(o.cli, nargs="?", const=o.const, default=o.text, help=o.help)
        elif o.parse is not None:
            parser.add_argument(o.cli, default=None if o.default is BY_KIND else o.text, help=o.help)
        elif o.name == "split":   # no default: the file's kind decides
            parser.add_argument(o.cli, choices=SPLITS, help=o.help)
        else:
            parser.add_argument(o.cli, type=o.kind, default=None if o.default is BY_KIND else o.default,
                                required=o.required, help=o.help)


def from_args(args) -> dict:
    """The keywords given; an option the model kind sets is left out where its flag is not given."""
    out = {}
    for o in OPTIONS:
        v = getattr(args, o.cli[2:].replace("-", "_"))
        if o.old:
            v = renamed("fit", v, getattr(args, "old_" + o.name), o.text if o.parse is not None else o.default, o.cli, o.old)
        if v is None and o.default is BY_KIND:
            continue
        out[o.name] = o.parse(v) if o.parse is not None else v
    return out
