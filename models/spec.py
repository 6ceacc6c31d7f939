"""The framework-neutral model spec: one frozen record both frameworks build from.

`ModelSpec(kind, dof, hidden, activation, init, dtype, extra_inputs, n_out, angle_wrap, input_scale, periodic,
own)`: the fields every kind has, and `own`, the record of the fields only its kind has (`models.kinds`:
`Lnn`, `Hnn`, `Delan`, `Lgn`, `User`, `Baseline`; each checks itself). The constructor also takes the own
fields by their flat names (`ModelSpec(kind="lgn", dof=10, lgn_radius=2)`, or on top of `own`, as
`dataclasses.replace` gives them) and builds the record; a field of another kind is refused unless at its
default. Unknown names and bad values raise ValueError naming the field and what is valid.

`to_dict()` is the flat form, plain JSON types, every cache key and registration hash is built from: the
common fields, then every kind's fields by flat name, another kind's at its default (`formulation`,
`delan_eps`, `delan_diag_offset`, `lgn_radius` are in every spec's form), except `WHEN_SET`, the fields added
after keys were made, written only when set so that a spec without them keeps its key. `from_dict` reads it.

The MLP's input and output widths (`mlp_sizes`) follow the kind's `Capability.mlp_input`, `scalar_output`
and `mlp_head`; x = input_scale * the features:
  "state" (baseline, lnn, hnn, user): [q, qdot(, gamma(qdot)), extra]  (2*dof + p + extra_inputs, 3*dof + ...
          with lorentz_factor) -> 1, or n_out (default dof) where the output is not a scalar
  "q" (delan):           q (dof + p) -> hidden[-1], trunk only (every layer activated); heads in `models.params`
  "neighbours" (lgn):    [q_nb, qdot_nb] of one node's 2r+1 neighbours (2*(2r+1)) -> 1
p = len(periodic): the q part (q, or x for the hnn) has each coordinate k in order, as q_k or, for k in
`periodic`, as the pair (cos q_k, sin q_k); e.g. dof 2, periodic (0,): [cos q_0, sin q_0, q_1] (dof + p wide).
"""
from __future__ import annotations

from dataclasses import dataclass

from lagbench.models.activations import ACTIVATIONS
from lagbench.models.kinds import (
    CAPABILITIES,
    FLAT_DEFAULTS,
    FORMULATIONS,
    KINDS,
    USER_CAPABILITY,
    USER_KIND,
    Capability,
    capability,
    flat_of,
    own_record,
)
from lagbench.validate import check, flag, integer, integers, is_integer, one_of, real

__all__ = ["CAPABILITIES", "DTYPES", "FORMULATIONS", "INITS", "KINDS", "USER_CAPABILITY", "USER_KIND", "Capability",
           "ModelSpec", "capability"]

INITS = ("cranmer2020", "pytorch_default", "xavier", "kaiming")
DTYPES = ("float32", "float64")
COMMON = ("kind", "dof", "hidden", "activation", "init", "dtype", "extra_inputs", "n_out", "angle_wrap",
          "input_scale", "periodic")
# the flat form's keys, in the order it writes them
FLAT_KEYS = ("kind", "dof", "hidden", "activation", "init", "dtype", "extra_inputs", "formulation", "n_out",
             "angle_wrap", "input_scale", "delan_eps", "delan_diag_offset", "lgn_radius", "lorentz_factor",
             "dissipation", "periodic", "factory", "factory_source", "scale_q_before_grad", "even_velocity")
WHEN_SET = ("lorentz_factor", "dissipation", "periodic", "factory", "factory_source", "scale_q_before_grad",
            "even_velocity")


@dataclass(frozen=True, init=False)
class ModelSpec:
    """What a model is, independent of the framework.

    dof: degrees of freedom (trailing dim of q); for lgn the nominal grid size (any n at call time).
    hidden: hidden layer widths, e.g. (600, 600, 600).
    extra_inputs: extra MLP inputs not differentiated (e.g. the relativistic field g, or tau/qddot
        for a baseline), shape (..., extra_inputs); for kinds whose capability has `extra_inputs`.
    n_out: the output width of a kind without a scalar output (the baseline; default dof); None or 1 for the
        others, unused by delan.
    angle_wrap: wrap q to [-pi, pi) before the MLP (discontinuous at the wrap; `periodic` is smooth).
    input_scale: per-feature multipliers of the MLP input vector (length = MLP input width).
    periodic: for kinds whose capability has `periodic`: the indices (sorted, unique, in [0, dof)) of the
        coordinates of q the MLP sees as the pair (cos q_k, sin q_k) instead of q_k (angles recorded
        unwrapped): the model is exactly 2 pi periodic in them; the others stay linear. Not with angle_wrap.
    own: the record of the kind's own fields (`models.kinds`); the kind's defaults where not given.
    """

    kind: str
    dof: int
    hidden: tuple
    activation: str
    init: str
    dtype: str
    extra_inputs: int
    n_out: int | None
    angle_wrap: bool
    input_scale: tuple | None
    periodic: tuple
    own: object

    def __init__(self, kind: str, dof: int, hidden=(600, 600, 600), activation: str = "softplus",
                 init: str = "cranmer2020", dtype: str = "float32", extra_inputs: int = 0, n_out: int | None = None,
                 angle_wrap: bool = False, input_scale=None, periodic=(), own=None, **own_fields):
        cap = capability(one_of("kind", kind, (*KINDS, USER_KIND)))
        values = {"kind": kind, "dof": integer("dof", dof, low=1), "hidden": integers("hidden", hidden, low=1),
                  "activation": one_of("activation", activation, ACTIVATIONS), "init": one_of("init", init, INITS),
                  "dtype": one_of("dtype", dtype, DTYPES),
                  "extra_inputs": integer("extra_inputs", extra_inputs, low=0),
                  "n_out": None if n_out is None else integer("n_out", n_out, low=1),
                  "angle_wrap": flag("angle_wrap", angle_wrap),
                  "periodic": _periodic(periodic, dof), "own": own_record(kind, own_fields, own)}
        for name, v in values.items():
            object.__setattr__(self, name, v)
        check(not self.extra_inputs or cap.extra_inputs, f"kind {kind!r} takes no extra_inputs (got {self.extra_inputs})")
        check(self.n_out in (None, 1) or not cap.scalar_output,
              f"kind {kind!r} has a scalar output; n_out must be None or 1, got {self.n_out}")
        check(not self.periodic or cap.periodic, f"periodic is for kinds "
              f"{', '.join(k for k in KINDS if CAPABILITIES[k].periodic)}, not {kind!r}")
        check(not (self.periodic and self.angle_wrap),
              "periodic and angle_wrap exclude each other: cos and sin are periodic already")
        if input_scale is not None:
            check(isinstance(input_scale, list | tuple), f"input_scale must be a sequence of numbers, got {input_scale!r}")
            input_scale = tuple(float(real("input_scale entry", s)) for s in input_scale)
            check(len(input_scale) == self.mlp_sizes()[0], f"input_scale needs {self.mlp_sizes()[0]} entries (the "
                  f"MLP input width), got {len(input_scale)}")
        object.__setattr__(self, "input_scale", input_scale)
        self.own.check_spec(self)

    @property
    def dissipation(self) -> bool:
        """A learned Rayleigh dissipation (the own field of kinds whose capability has `dissipation`)."""
        return getattr(self.own, "dissipation", False)

    @property
    def lorentz_factor(self) -> bool:
        """The Lorentz factor of qdot as an MLP input (the own field of kinds whose capability has it)."""
        return getattr(self.own, "lorentz_factor", False)

    def q_width(self) -> int:
        """Width of the MLP's q part: dof, plus one for each periodic coordinate (its cos and sin)."""
        return self.dof + len(self.periodic)

    def mlp_sizes(self) -> tuple:
        """Layer widths of the (trunk) MLP, input first: e.g. (4, 600, 600, 600, 1)."""
        cap = capability(self.kind)
        if cap.mlp_input == "q":
            n_in = self.q_width()
        elif cap.mlp_input == "neighbours":
            n_in = 2 * (2 * self.own.radius + 1)
        else:
            n_in = self.q_width() + (2 if self.lorentz_factor else 1) * self.dof + self.extra_inputs
        if not cap.mlp_head:
            return (n_in, *self.hidden)
        return (n_in, *self.hidden, 1 if cap.scalar_output else (self.n_out or self.dof))

    def to_dict(self) -> dict:
        common = {name: getattr(self, name) for name in COMMON}
        common.update(hidden=list(self.hidden), periodic=list(self.periodic),
                      input_scale=None if self.input_scale is None else list(self.input_scale))
        values = {**common, **FLAT_DEFAULTS, **flat_of(self.own)}
        return {k: values[k] for k in FLAT_KEYS if k not in WHEN_SET or values[k]}

    @classmethod
    def from_dict(cls, d: dict) -> ModelSpec:
        return cls(**d)


def _periodic(periodic, dof) -> tuple:
    check(isinstance(periodic, list | tuple) and all(is_integer(k) and 0 <= k < dof for k in periodic),
          f"periodic must be indices of q's coordinates, ints in [0, {dof}), got {periodic!r}")
    check(list(periodic) == sorted(set(periodic)), f"periodic indices must be unique and sorted, got {tuple(periodic)}")
    return tuple(int(k) for k in periodic)

