"""The model kinds: one table of what each kind is and can do, and one small record per kind of the fields
only that kind has.

`CAPABILITIES[kind]` (`Capability`) is the one list of kinds: `KINDS` is its keys, both frameworks' `build`
registries register from it, and every question "which kinds can ..." reads its columns. `capability(kind)`
answers for the user's kind ("user", `USER_CAPABILITY`) as well.

Each kind's own fields are a frozen record that checks itself (`ModelSpec.own`):
  `Baseline()`                                           none: its output width is the spec's n_out
  `Lnn(formulation, lorentz_factor, dissipation, scale_q_before_grad, even_velocity)`
  `Hnn(lorentz_factor, dissipation)`
  `Delan(eps, diag_offset, dissipation)`
  `Lgn(formulation, radius)`
  `User(factory, factory_source)`
Grouped by kind, not by feature: the fields two kinds share (`dissipation`, `lorentz_factor`, `formulation`)
mean one thing but are checked against the kind (an LNN's dissipation needs its fast formulation; the LNN and
the LGN accept different formulations). A capability's `dissipation` and `lorentz_factor` columns say which
records hold that field.

The flat form (`ModelSpec.to_dict`) names a field by `flat_name`: the record's field name, or
"<kind>_<field>" where the record's name is short (`Delan.eps` is "delan_eps", `Lgn.radius` "lgn_radius").
`FLAT_DEFAULTS`: flat name -> the default, one for all records that hold it. `own_record(kind, flat, own)`
makes a kind's record from flat fields; a flat field of another kind is accepted at its default only (every
spec's flat form writes some of them, so that keys made before the records stay) and refused otherwise,
naming the kinds it is for.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

from lagbench.validate import check, flag, integer, one_of, real


class OwnFields:
    """What every kind's record has: `FLAT` (field -> flat name, where they differ) and `check_spec(spec)`,
    the relations of its fields to the spec's common fields (none unless a record says)."""

    FLAT: ClassVar[dict] = {}

    def check_spec(self, spec) -> None:
        pass


@dataclass(frozen=True)
class Baseline(OwnFields):
    """The baseline MLP maps [q, qdot, extra] to n_out values: nothing of its own."""


@dataclass(frozen=True)
class Lnn(OwnFields):
    """formulation: "fast" | "paper" (`models.jax.lnn.euler_lagrange_info`).
    lorentz_factor: the MLP also sees gamma_k = (1 - qdot_k^2)^(-1/2) of every velocity component (c = 1), after
        qdot; a kinematic feature of a speed-limited system, differentiated through like qdot.
    dissipation: (fast formulation) a learned Rayleigh dissipation D = 1/2 sum_k b_k qdot_k^2 with
        b_k = softplus(raw_k) >= 0 (parameter "dissipation.raw", (dof,)), entering the Euler-Lagrange equation
        as -s dD/dqdot = -s b * qdot, s = sign(trace of the velocity Hessian): linear viscous friction per
        coordinate. A Lagrangian learned from accelerations is fixed only up to a factor, of either sign; s
        orients the force against the learned energy s E, so the friction the data see, b / |factor|, is never
        negative.
    scale_q_before_grad: with an input_scale, the original LNN code's convention (its relativistic notebook
        forms q / 10 before jax.grad): the Euler-Lagrange equation takes L's q-derivatives with respect to the
        scaled q part x_q = s_q f(q), not q, so neither dL/dq = (df/dq)^T dL/dx_q nor the mixed term's tangent
        (df/dq) qdot carries the chain-rule factor s_q; H, qdot and the velocity side are unchanged. With s_q the
        same on every slot, qddot is the differentiated-through one divided by s_q. The model's `lagrangian` has
        the same value; its q-derivative is dL/dx_q chained through f only.
    even_velocity: L(q, qdot) = (N(q, qdot) + N(q, -qdot)) / 2 with N the MLP: even in qdot by construction, the
        time-reversal symmetry of a mechanical system without magnetic or gyroscopic forces. The conservative
        part then has no force odd in qdot, so where the data lose energy the dissipation is the only odd force
        (an MLP of qdot itself learns spurious odd forces that take a share of the friction). Its Euler-Lagrange
        terms (H, dL/dq - J qdot) are the average of N's at (q, qdot) and (q, -qdot): twice the MLP's work."""

    formulation: str = "fast"
    lorentz_factor: bool = False
    dissipation: bool = False
    scale_q_before_grad: bool = False
    even_velocity: bool = False

    def __post_init__(self):
        one_of("lnn formulation", self.formulation, CAPABILITIES["lnn"].formulations)
        for name in ("lorentz_factor", "dissipation", "scale_q_before_grad", "even_velocity"):
            flag(name, getattr(self, name))
        check(not self.dissipation or self.formulation == "fast",
              f"dissipation is for the LNN in its fast formulation, not {self.formulation!r}")

    def check_spec(self, spec) -> None:
        check(not self.scale_q_before_grad or spec.input_scale is not None,
              "scale_q_before_grad is for an lnn with an input_scale (the scaled q it differentiates in); this one "
              "has none")


@dataclass(frozen=True)
class Hnn(OwnFields):
    """lorentz_factor: as the LNN's, the momentum-side input y also enters as gamma(y).
    dissipation: ydot = -dH/dx - b * dH/dy (the force on the momentum, xdot = dH/dy the velocity), b as the LNN's."""

    lorentz_factor: bool = False
    dissipation: bool = False

    def __post_init__(self):
        for name in ("lorentz_factor", "dissipation"):
            flag(name, getattr(self, name))


@dataclass(frozen=True)
class Delan(OwnFields):
    """eps: epsilon of M = L L^T + eps I. diag_offset: diag(L) = softplus(raw + offset).
    dissipation: tau = M qddot + c + g + b * qdot, b as the LNN's (M is positive definite: no orientation)."""

    eps: float = 0.01
    diag_offset: float = 2.0
    dissipation: bool = False
    FLAT: ClassVar[dict] = {"eps": "delan_eps", "diag_offset": "delan_diag_offset"}

    def __post_init__(self):
        real("delan_eps", self.eps, low=0)
        real("delan_diag_offset", self.diag_offset)
        flag("dissipation", self.dissipation)


@dataclass(frozen=True)
class Lgn(OwnFields):
    """formulation: "banded" (alias "fast") | "dense" | "paper" (`models.jax.lgn`).
    radius: neighbours on each side of a node in the density MLP."""

    formulation: str = "fast"
    radius: int = 1
    FLAT: ClassVar[dict] = {"radius": "lgn_radius"}

    def __post_init__(self):
        one_of("lgn formulation", self.formulation, CAPABILITIES["lgn"].formulations)
        object.__setattr__(self, "radius", integer("lgn_radius", self.radius, low=1))


@dataclass(frozen=True)
class User(OwnFields):
    """factory: "module:function" (or "path/file.py:function") returning the torch.nn.Module or equinox Module;
    factory_source: the sha256 (16 hex digits) of the file that defines it, so an edited module is a new spec
    and never reuses a cached training (`models.user`)."""

    factory: str | None = None
    factory_source: str | None = None

    def __post_init__(self):
        check(isinstance(self.factory, str) and self.factory != "",
              f"kind 'user' needs a factory (module:function), got {self.factory!r}")
        check(self.factory_source is None or isinstance(self.factory_source, str),
              f"factory_source must be a file's hash or None, got {self.factory_source!r}")


def flat_name(record_class, name: str) -> str:
    return record_class.FLAT.get(name, name)


def flat_of(record) -> dict:
    """The record's fields by flat name."""
    return {flat_name(type(record), f.name): getattr(record, f.name) for f in dataclasses.fields(record)}


@dataclass(frozen=True)
class Capability:
    """One model kind: where its code is and what it can do.

    model_class: the class name in `models/jax/<kind>.py` and `models/torch/<kind>.py` (`build` imports it
    by name). tasks: the protocol tasks it trains on; lagrangian_hessian: its q-double-dot goes through a
    learned velocity Hessian d2L/dqdot2 (the Hessian probe watches it); torch_compile: formulation -> how
    PyTorch compiles it ahead of time: "aot" (torch.export + AOTInductor, any batch) or "traced" (torch.func
    inside: make_fx, then compiled per batch size). record: the class of its own fields. formulations: the
    formulations it accepts (empty: it has one). extra_inputs: it takes extra MLP inputs; periodic: its MLP
    may see coordinates as (cos, sin) (`ModelSpec.periodic`). mlp_input: what its MLP reads: "state" ([q,
    qdot(, gamma(qdot)), extra]), "q" (q only) or "neighbours" (each node's 2r+1 neighbours' q and qdot);
    scalar_output: its MLP ends in one output (n_out must be None or 1); mlp_head: its MLP ends in an output
    layer (False: a trunk whose every layer is activated, the heads its own, `models.params`). energy: a
    fitted model of the kind gives the system's energy (`lagbench.replication.fit.load`)."""

    model_class: str
    tasks: tuple
    lagrangian_hessian: bool
    torch_compile: dict
    record: type
    formulations: tuple = ()
    extra_inputs: bool = True
    periodic: bool = True
    mlp_input: str = "state"
    scalar_output: bool = True
    mlp_head: bool = True
    energy: bool = False

    @property
    def dissipation(self) -> bool:
        """It may learn a Rayleigh dissipation (its record has the field)."""
        return "dissipation" in {f.name for f in dataclasses.fields(self.record)}

    @property
    def lorentz_factor(self) -> bool:
        """Its MLP may take the Lorentz factor of qdot (its record has the field)."""
        return "lorentz_factor" in {f.name for f in dataclasses.fields(self.record)}


CAPABILITIES = {
    "baseline": Capability("Baseline", ("acceleration", "inverse_dynamics"), False, {"-": "aot"}, Baseline,
                           scalar_output=False),
    "lnn": Capability("LNN", ("acceleration",), True, {"fast": "aot", "paper": "traced"}, Lnn,
                      formulations=("fast", "paper"), energy=True),
    "hnn": Capability("HNN", ("hamiltonian",), False, {"-": "aot"}, Hnn, energy=True),
    "delan": Capability("DeLaN", ("acceleration", "inverse_dynamics"), False, {"-": "aot"}, Delan,
                        extra_inputs=False, mlp_input="q", scalar_output=False, mlp_head=False, energy=True),
    "lgn": Capability("LGN", ("acceleration",), True, {"banded": "aot", "dense": "traced"}, Lgn,
                      formulations=("fast", "banded", "dense", "paper"), extra_inputs=False, periodic=False,
                      mlp_input="neighbours"),
}
KINDS = tuple(CAPABILITIES)
# a user's torch.nn.Module or equinox Module (`lagbench run --add-model`, `models.user`), built by its factory;
# a kind of the spec, not of the suite (one framework, no parity: `KINDS` leaves it out)
USER_KIND = "user"
USER_CAPABILITY = Capability("UserModel", ("acceleration", "hamiltonian"), False, {}, User, extra_inputs=False,
                             periodic=False, scalar_output=False)
FORMULATIONS = tuple(dict.fromkeys(f for c in CAPABILITIES.values() for f in c.formulations))


def capability(kind: str) -> Capability:
    return USER_CAPABILITY if kind == USER_KIND else CAPABILITIES[kind]


def _holders() -> dict:
    """flat name -> {kind: the record's default}, over every kind."""
    out = {}
    for kind in (*KINDS, USER_KIND):
        cls = capability(kind).record
        for f in dataclasses.fields(cls):
            default = None if f.default is dataclasses.MISSING else f.default
            out.setdefault(flat_name(cls, f.name), {})[kind] = default
    return out


def _flat_defaults() -> dict:
    out = {}
    for name, by_kind in HOLDERS.items():
        if len(set(by_kind.values())) != 1:   # the flat form writes one default for the kinds without the field
            raise AssertionError(f"{name}: the records that hold it disagree on its default: {by_kind}")
        out[name] = next(iter(by_kind.values()))
    return out


HOLDERS = _holders()
FLAT_DEFAULTS = _flat_defaults()


def own_record(kind: str, flat: dict, own=None):
    """The record of `kind` from flat fields (flat name -> value) on top of `own` (or the kind's defaults)."""
    cls = capability(kind).record
    names = {flat_name(cls, f.name): f.name for f in dataclasses.fields(cls)}
    mine = {}
    for key, v in flat.items():
        if key in names:
            mine[names[key]] = v
        elif key not in FLAT_DEFAULTS:
            raise TypeError(f"ModelSpec got an unexpected keyword argument {key!r}")
        elif v != FLAT_DEFAULTS[key]:
            kinds = tuple(HOLDERS[key])
            raise ValueError(f"{key} is for kind{'s' if len(kinds) > 1 else ''} {', '.join(kinds)}, not {kind!r} "
                             f"(the own fields of {kind!r}: {', '.join(names) or 'none'})")
    if own is None:
        return cls(**mine)
    check(type(own) is cls, f"kind {kind!r} holds its own fields in a {cls.__name__}, got {own!r}")
    return dataclasses.replace(own, **mine) if mine else own
