"""The framework-neutral model spec: one frozen dataclass both frameworks build from.

`ModelSpec(kind, dof, hidden, activation, init, dtype, extra_inputs, formulation, n_out,
angle_wrap, input_scale, delan_eps, delan_diag_offset, lgn_radius, lorentz_factor, dissipation, periodic, factory,
factory_source, scale_q_before_grad)` is
validated on creation (unknown names and bad sizes raise ValueError listing what is valid) and round-trips
through `to_dict()` / `from_dict()` (plain JSON types).

Per kind, the MLP input width and output width (see `mlp_sizes`); x = input_scale * the features:
  baseline: [q, qdot, extra]            (2*dof + p + extra_inputs) -> n_out (default dof)
  lnn, hnn: [q, qdot, extra] / [x, y, extra]  (2*dof + p + extra_inputs) -> 1; with lorentz_factor
            [q, qdot, gamma(qdot), extra]   (3*dof + p + extra_inputs) -> 1
  delan:    q (dof + p) -> hidden[-1], trunk only (every layer activated); heads in `models.params`
  lgn:      [q_nb, qdot_nb] of one node's 2r+1 neighbours (2*(2r+1)) -> 1
p = len(periodic): the q part (q, or x for the hnn) has each coordinate k in order, as q_k or, for k in
`periodic`, as the pair (cos q_k, sin q_k); e.g. dof 2, periodic (0,): [cos q_0, sin q_0, q_1] (dof + p wide).
Formulations: lnn "fast" | "paper"; lgn "banded" (alias "fast") | "dense" | "paper";
other kinds ignore it.
`CAPABILITIES[kind]` (`Capability`): the one table of kinds (class name, tasks, formulations, how PyTorch
compiles it); `KINDS` is its keys, and `models.jax.build` / `models.torch.build` register from it.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from lagbench.models.activations import ACTIVATIONS


@dataclass(frozen=True)
class Capability:
    """One model kind: where its code is and what it can do. This table is the one list of kinds:
    `KINDS`, both frameworks' `build` registries and every consumer read it instead of keeping their own.

    model_class: the class name in `models/jax/<kind>.py` and `models/torch/<kind>.py` (`build` imports it
    by name). tasks: the protocol tasks it trains on; lagrangian_hessian: its q-double-dot goes through a
    learned velocity Hessian d2L/dqdot2 (the Hessian probe watches it); torch_compile: formulation -> how
    PyTorch compiles it ahead of time: "aot" (torch.export + AOTInductor, any batch) or "traced" (torch.func
    inside: make_fx, then compiled per batch size). formulations: the spec formulations it accepts (empty:
    it has one and ignores the field); extra_inputs: it takes extra MLP inputs; scalar_output: its MLP
    ends in one output (n_out must be None or 1)."""

    model_class: str
    tasks: tuple
    lagrangian_hessian: bool
    torch_compile: dict
    formulations: tuple = ()
    extra_inputs: bool = True
    scalar_output: bool = True


CAPABILITIES = {
    "baseline": Capability("Baseline", ("acceleration", "inverse_dynamics"), False, {"-": "aot"},
                           scalar_output=False),
    "lnn": Capability("LNN", ("acceleration",), True, {"fast": "aot", "paper": "traced"},
                      formulations=("fast", "paper")),
    "hnn": Capability("HNN", ("hamiltonian",), False, {"-": "aot"}),
    "delan": Capability("DeLaN", ("acceleration", "inverse_dynamics"), False, {"-": "aot"},
                        extra_inputs=False, scalar_output=False),
    "lgn": Capability("LGN", ("acceleration",), True, {"banded": "aot", "dense": "traced"},
                      formulations=("fast", "banded", "dense", "paper"), extra_inputs=False),
}
KINDS = tuple(CAPABILITIES)
# a user's torch.nn.Module or equinox Module (`lagbench run --add-model`, `models.user`), built by its factory;
# a kind of the spec, not of the suite (one framework, no parity: `KINDS` leaves it out)
USER_KIND = "user"
USER_CAPABILITY = Capability("UserModel", ("acceleration", "hamiltonian"), False, {}, extra_inputs=False,
                             scalar_output=False)


def capability(kind: str) -> Capability:
    return USER_CAPABILITY if kind == USER_KIND else CAPABILITIES[kind]
INITS = ("cranmer2020", "pytorch_default", "xavier", "kaiming")
FORMULATIONS = ("fast", "paper", "dense", "banded")
DTYPES = ("float32", "float64")


DISSIPATIVE_KINDS = ("lnn", "hnn", "delan")   # kinds that may learn a Rayleigh dissipation (`ModelSpec.dissipation`)
LORENTZ_KINDS = ("lnn", "hnn")   # kinds whose MLP may take the Lorentz factor of qdot (`ModelSpec.lorentz_factor`)
PERIODIC_KINDS = ("baseline", "lnn", "hnn", "delan")   # kinds whose MLP may see angles as cos, sin (`ModelSpec.periodic`)


def _choices(what: str, value, valid) -> None:
    if value not in valid:
        raise ValueError(f"unknown {what} {value!r}; valid: {', '.join(map(str, valid))}")


@dataclass(frozen=True)
class ModelSpec:
    """What a model is, independent of the framework.

    dof: degrees of freedom (trailing dim of q); for lgn the nominal grid size (any n at call time).
    hidden: hidden layer widths, e.g. (600, 600, 600).
    extra_inputs: extra MLP inputs not differentiated (e.g. the relativistic field g, or tau/qddot
        for a baseline), shape (..., extra_inputs).
    n_out: baseline output width (default dof); must be None or 1 for lnn/hnn/lgn; unused by delan.
    angle_wrap: wrap q to [-pi, pi) before the MLP (discontinuous at the wrap; `periodic` is smooth).
    input_scale: per-feature multipliers of the MLP input vector (length = MLP input width).
    delan_eps: epsilon of M = L L^T + eps I. delan_diag_offset: diag(L) = softplus(raw + offset).
    lgn_radius: neighbours on each side of a node in the density MLP.
    lorentz_factor: lnn, hnn: the MLP also sees gamma_k = (1 - qdot_k^2)^(-1/2) of every velocity component
        (the speed of light c = 1), after qdot; a kinematic feature of a speed-limited system, differentiated
        through like qdot. Left out of `to_dict` while False, so older specs keep their training keys.
    dissipation: lnn (fast formulation): a learned Rayleigh dissipation D = 1/2 sum_k b_k qdot_k^2 with
        b_k = softplus(raw_k) >= 0 (parameter "dissipation.raw", (dof,)), entering the Euler-Lagrange equation
        as -s dD/dqdot = -s b * qdot, s = sign(trace of the velocity Hessian): linear viscous friction per
        coordinate. A Lagrangian learned from accelerations is fixed only up to a factor, of either sign; s
        orients the force against the learned energy s E, so the friction the data see, b / |factor|, is never
        negative. hnn: ydot = -dH/dx - b * dH/dy (the force on the momentum, xdot = dH/dy the velocity);
        delan: tau = M qddot + c + g + b * qdot (M is positive definite: no orientation to fix). Left out of
        `to_dict` while False.
    periodic: baseline, lnn, hnn, delan: the indices (sorted, unique, in [0, dof)) of the coordinates of q the
        MLP sees as the pair (cos q_k, sin q_k) instead of q_k (angles recorded unwrapped): the model is exactly
        2 pi periodic in them; the others stay linear. Not with angle_wrap. Left out of `to_dict` while empty.
    factory, factory_source: kind "user" only: "module:function" (or "path/file.py:function") returning
        the torch.nn.Module or equinox Module, and the sha256 (16 hex digits) of the file that defines it, so an edited
        module is a new spec and never reuses a cached training (`models.user`). Left out while None.
    scale_q_before_grad: lnn with an input_scale: the original LNN code's convention (its relativistic notebook
        forms q / 10 before jax.grad): the Euler-Lagrange equation takes L's q-derivatives with respect to the
        scaled q part x_q = s_q f(q), not q, so neither dL/dq = (df/dq)^T dL/dx_q nor the mixed term's tangent
        (df/dq) qdot carries the chain-rule factor s_q; H, qdot and the velocity side are unchanged. With s_q the
        same on every slot, qddot is the differentiated-through one divided by s_q. The model's `lagrangian` has the
        same value; its q-derivative is dL/dx_q chained through f only. Left out of `to_dict` while False.
    """

    kind: str
    dof: int
    hidden: tuple = (600, 600, 600)
    activation: str = "softplus"
    init: str = "cranmer2020"
    dtype: str = "float32"
    extra_inputs: int = 0
    formulation: str = "fast"
    n_out: int | None = None
    angle_wrap: bool = False
    input_scale: tuple | None = None
    delan_eps: float = 0.01
    delan_diag_offset: float = 2.0
    lgn_radius: int = 1
    lorentz_factor: bool = False
    dissipation: bool = False
    periodic: tuple = ()
    factory: str | None = None
    factory_source: str | None = None
    scale_q_before_grad: bool = False

    def __post_init__(self):
        _choices("kind", self.kind, (*KINDS, USER_KIND))
        _choices("activation", self.activation, ACTIVATIONS)
        _choices("init", self.init, INITS)
        _choices("dtype", self.dtype, DTYPES)
        _choices("formulation", self.formulation, FORMULATIONS)
        cap = capability(self.kind)
        if cap.formulations:
            _choices(f"formulation for kind {self.kind!r}", self.formulation, cap.formulations)
        if isinstance(self.dof, bool) or not isinstance(self.dof, int) or self.dof < 1:
            raise ValueError(f"dof must be an int >= 1, got {self.dof!r}")
        hidden = tuple(self.hidden) if isinstance(self.hidden, (list, tuple)) else None
        if not hidden or any(isinstance(h, bool) or not isinstance(h, int) or h < 1 for h in hidden):
            raise ValueError(f"hidden must be a non-empty sequence of ints >= 1, got {self.hidden!r}")
        object.__setattr__(self, "hidden", hidden)
        if not isinstance(self.extra_inputs, int) or self.extra_inputs < 0:
            raise ValueError(f"extra_inputs must be an int >= 0, got {self.extra_inputs!r}")
        if self.extra_inputs and not cap.extra_inputs:
            raise ValueError(f"kind {self.kind!r} takes no extra_inputs (got {self.extra_inputs})")
        if self.n_out is not None:
            if not isinstance(self.n_out, int) or self.n_out < 1:
                raise ValueError(f"n_out must be None or an int >= 1, got {self.n_out!r}")
            if cap.scalar_output and self.n_out != 1:
                raise ValueError(f"kind {self.kind!r} has a scalar output; n_out must be None or 1")
        if not isinstance(self.lgn_radius, int) or self.lgn_radius < 1:
            raise ValueError(f"lgn_radius must be an int >= 1, got {self.lgn_radius!r}")
        if not isinstance(self.lorentz_factor, bool):
            raise ValueError(f"lorentz_factor must be True or False, got {self.lorentz_factor!r}")
        if self.lorentz_factor and self.kind not in LORENTZ_KINDS:
            raise ValueError(f"lorentz_factor is for kinds {', '.join(LORENTZ_KINDS)}, not {self.kind!r}")
        if not isinstance(self.dissipation, bool):
            raise ValueError(f"dissipation must be True or False, got {self.dissipation!r}")
        if self.dissipation and (self.kind not in DISSIPATIVE_KINDS or (self.kind == "lnn" and self.formulation != "fast")):
            raise ValueError(f"dissipation is for kinds {', '.join(DISSIPATIVE_KINDS)} (the LNN in its fast "
                             f"formulation), not {self.kind!r} ({self.formulation})")
        self._check_periodic()
        if (self.kind == USER_KIND) != (self.factory is not None):
            raise ValueError("kind 'user' needs a factory (module:function), and only it takes one")
        if not self.delan_eps >= 0:
            raise ValueError(f"delan_eps must be >= 0, got {self.delan_eps!r}")
        if self.input_scale is not None:
            scale = tuple(float(s) for s in self.input_scale)
            if len(scale) != self.mlp_sizes()[0]:
                raise ValueError(f"input_scale needs {self.mlp_sizes()[0]} entries (the MLP input width), "
                                 f"got {len(scale)}")
            object.__setattr__(self, "input_scale", scale)
        if not isinstance(self.scale_q_before_grad, bool):
            raise ValueError(f"scale_q_before_grad must be True or False, got {self.scale_q_before_grad!r}")
        if self.scale_q_before_grad and (self.kind != "lnn" or self.input_scale is None):
            raise ValueError(f"scale_q_before_grad is for kind 'lnn' with an input_scale, not {self.kind!r} "
                             f"(input_scale {self.input_scale})")

    def _check_periodic(self):
        periodic = self.periodic
        if not isinstance(periodic, (list, tuple)) or any(
                isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < self.dof for k in periodic):
            raise ValueError(f"periodic must be indices of q's coordinates, ints in [0, {self.dof}), got {periodic!r}")
        if list(periodic) != sorted(set(periodic)):
            raise ValueError(f"periodic indices must be unique and sorted, got {tuple(periodic)}")
        object.__setattr__(self, "periodic", tuple(periodic))
        if periodic and self.kind not in PERIODIC_KINDS:
            raise ValueError(f"periodic is for kinds {', '.join(PERIODIC_KINDS)}, not {self.kind!r}")
        if periodic and self.angle_wrap:
            raise ValueError("periodic and angle_wrap exclude each other: cos and sin are periodic already")

    def q_width(self) -> int:
        """Width of the MLP's q part: dof, plus one for each periodic coordinate (its cos and sin)."""
        return self.dof + len(self.periodic)

    def mlp_sizes(self) -> tuple:
        """Layer widths of the (trunk) MLP, input first: e.g. (4, 600, 600, 600, 1)."""
        if self.kind == "delan":
            return (self.q_width(), *self.hidden)
        if self.kind == "lgn":
            return (2 * (2 * self.lgn_radius + 1), *self.hidden, 1)
        n_in = self.q_width() + (2 if self.lorentz_factor else 1) * self.dof + self.extra_inputs
        n_out = 1 if capability(self.kind).scalar_output else (self.n_out or self.dof)
        return (n_in, *self.hidden, n_out)

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["hidden"] = list(self.hidden)
        d["input_scale"] = None if self.input_scale is None else list(self.input_scale)
        d["periodic"] = list(self.periodic)
        for k in ("lorentz_factor", "dissipation", "periodic", "scale_q_before_grad"):
            if not d[k]:
                del d[k]
        for k in ("factory", "factory_source"):
            if d[k] is None:
                del d[k]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> ModelSpec:
        d = dict(d)
        d["hidden"] = tuple(d.get("hidden", cls.hidden))
        if d.get("input_scale") is not None:
            d["input_scale"] = tuple(d["input_scale"])
        if "periodic" in d:
            d["periodic"] = tuple(d["periodic"])
        return cls(**d)
