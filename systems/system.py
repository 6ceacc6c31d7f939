"""``System``: a ``Definition`` with bound parameter values, and its generated callables.

Every numerical method takes arrays of one backend ("numpy" | "jax" | "torch") with a trailing
axis of size ``dof`` and leading batch axes ``(...)``, and returns that backend's arrays in the
input's float dtype (float32 stays float32; anything else is float64):

- ``acceleration(q, qdot, backend, tau=None, **overrides)`` -> (..., dof)
- ``energy(q, qdot, ...)`` -> (...,);  ``canonical_momentum(q, qdot, ...)`` -> (..., dof);
  ``canonical_momentum_rate(q, qdot, ...)`` -> (..., dof): dp/dt (unforced), HNN's target
- ``velocity_hessian(q, qdot, ...)`` -> (..., dof, dof)  (d2L/dqdot2, defined for every system)
- ``mass_matrix(q, ...)`` -> (..., dof, dof); ``gravity(q, ...)`` -> (..., dof);
  ``coriolis(q, qdot, ...)`` -> (..., dof); ``coriolis_matrix(q, qdot, ...)`` -> (..., dof, dof):
  only where L = qdot^T M(q) qdot / 2 - V(q), else ``NotQuadraticError`` (a ValueError)
- ``inverse_dynamics(q, qdot, qddot, ...)`` -> (..., dof): the generalised force tau that
  produces qddot (torques for the arm; viscous friction included where the system has it)

``**overrides`` replace bound parameters for one call; each may be a scalar or an array
broadcastable to the batch shape (...). Generated sources are cached on disk (``systems.cache``)
keyed by a hash of the Lagrangian; compiled callables are cached in memory per backend.
"""

from __future__ import annotations

import json

import numpy as np
import sympy as sp

from lagbench.systems import backends, cache, codegen
from lagbench.systems.definition import Definition
from lagbench.systems.derive import Derivation, NotQuadraticError

_SOURCES: dict = {}
_FUNCS: dict = {}
_DERIVATIONS: dict = {}


def _derivation(d: Definition) -> Derivation:
    key = d.fingerprint()
    if key not in _DERIVATIONS:
        _DERIVATIONS[key] = Derivation(d)
    return _DERIVATIONS[key]


def _output(dv: Derivation, what: str) -> tuple:
    d = dv.d
    if what in ("acceleration", "acceleration_tau"):
        zero_tau = {} if what == "acceleration_tau" else {t: 0 for t in dv.tau_syms}
        acc = dv.acceleration
        if acc is not None:
            return "vector", [e.xreplace(zero_tau) for e in acc]
        return "solve", (dv.hessian, [e.xreplace(zero_tau) for e in dv.rhs])
    table = {
        "energy": lambda: ("scalar", dv.energy),
        "momentum": lambda: ("vector", dv.momentum),
        "momentum_rate": lambda: ("vector", dv.momentum_rate),
        "velocity_hessian": lambda: ("matrix", dv.hessian),
        "mass_matrix": lambda: ("matrix", dv.mass_matrix),
        "gravity": lambda: ("vector", dv.gravity),
        "coriolis": lambda: ("vector", dv.coriolis),
        "coriolis_matrix": lambda: ("matrix", dv.coriolis_matrix),
        "inverse_dynamics": lambda: ("vector", dv.inverse_dynamics),
    }
    if what not in table:
        raise KeyError(f"nothing named {what!r} is derived for {d.name!r}")
    return table[what]()


def _cache_name(d: Definition, what: str) -> str:
    return f"{d.name}-{what}-{cache.digest(codegen.CODEGEN_VERSION, d.fingerprint(), what)[:20]}"


def structure_of(d: Definition) -> dict:
    """The derived structure dict (cached on disk like the generated code)."""
    name = _cache_name(d, "structure")
    text = cache.load_text("codegen", name)
    if text is None:
        text = json.dumps(_derivation(d).structure)
        cache.store_text("codegen", name, text)
    return json.loads(text)


def source_of(d: Definition, what: str) -> str:
    """Generated source for ``what`` (memory cache, then disk cache, then derivation)."""
    name = _cache_name(d, what)
    if name in _SOURCES:
        return _SOURCES[name]
    if what in ("mass_matrix", "gravity", "coriolis", "coriolis_matrix") and not structure_of(d)[
        "quadratic_kinetic"
    ]:
        _derivation(d)._require_quadratic(what.replace("_", " "))
    src = cache.load_text("codegen", name)
    if src is None:
        dv = _derivation(d)
        inputs = {"q": d.q, "qdot": d.qdot, "qddot": dv.qddot_syms, "tau": dv.tau_syms}
        src = codegen.generate(what, _output(dv, what), inputs, d.param_symbols)
        cache.store_text("codegen", name, src)
    _SOURCES[name] = src
    return src


def _function(d: Definition, what: str, backend: str):
    key = (_cache_name(d, what), backend)
    if key not in _FUNCS:
        _FUNCS[key] = codegen.compile_source(source_of(d, what), what, backend, f"{d.name}.{what}")
    return _FUNCS[key]


def check_params(d: Definition, values: dict) -> dict:
    """Validate names and constraints; return float values for scalars, arrays untouched."""
    out = {}
    for k, v in values.items():
        if k not in d.params:
            valid = ", ".join(sorted(d.params)) or "(none)"
            raise ValueError(f"{d.name!r} has no parameter {k!r}; valid parameters: {valid}")
        constraint = d.params[k][2]
        if np.ndim(v) == 0 and backends.is_concrete(v) and not hasattr(v, "grad_fn"):
            v = float(v)
        if backends.is_concrete(v):
            arr = np.asarray(v if isinstance(v, float) else backends._to_numpy(v), dtype=float)
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{d.name!r}: parameter {k!r} must be finite")
            if constraint == "positive" and np.any(arr <= 0):
                raise ValueError(f"{d.name!r}: parameter {k!r} must be > 0 (got {v!r})")
            if constraint == "nonnegative" and np.any(arr < 0):
                raise ValueError(f"{d.name!r}: parameter {k!r} must be >= 0 (got {v!r})")
        out[k] = v
    return out


class System:
    """A physical system with bound parameters; see the module docstring for the methods."""

    def __init__(self, definition: Definition, **values):
        self.definition = definition
        defaults = {k: default for k, (_, default, _) in definition.params.items()}
        self._params = {**defaults, **check_params(definition, values)}
        if definition.validate is not None:
            definition.validate(self._params)

    # --- description -----------------------------------------------------------------
    name = property(lambda self: self.definition.name)
    dof = property(lambda self: self.definition.dof)
    lagrangian = property(lambda self: self.definition.lagrangian)
    q_symbols = property(lambda self: self.definition.q)
    qdot_symbols = property(lambda self: self.definition.qdot)
    options = property(lambda self: dict(self.definition.options))
    params = property(lambda self: dict(self._params))
    structure = property(lambda self: structure_of(self.definition))

    @property
    def param_symbols(self) -> dict:
        return {k: sym for k, (sym, _, _) in self.definition.params.items()}

    def bound_lagrangian(self) -> sp.Expr:
        """The Lagrangian with the bound parameter values substituted."""
        subs = {self.param_symbols[k]: v for k, v in self._params.items()}
        return self.definition.lagrangian.subs(subs)

    def __repr__(self) -> str:
        opts = "".join(f", {k}={v!r}" for k, v in self.definition.options.items())
        return f"System({self.name!r}, dof={self.dof}{opts}, params={self._params})"

    # --- numerics ----------------------------------------------------------------------
    def _call(self, what: str, backend: str, arrays: dict, overrides: dict):
        backends.check_backend(backend)
        dtype = backends.result_dtype(*arrays.values())
        conv = {}
        for arg, x in arrays.items():
            if x is None:
                conv[arg] = None
                continue
            x = backends.as_array(x, backend, dtype)
            if x.ndim == 0 or x.shape[-1] != self.dof:
                raise ValueError(
                    f"{self.name}.{what}: {arg} must have shape (..., {self.dof}); got {tuple(x.shape)}"
                )
            conv[arg] = x
        values = {**self._params, **check_params(self.definition, overrides)}
        params = [
            v if isinstance(v, float) else backends.as_array(v, backend, dtype) for v in values.values()
        ]
        shapes = [tuple(x.shape[:-1]) for x in conv.values() if x is not None]
        shapes += [tuple(p.shape) for p in params if not isinstance(p, float)]
        try:
            batch = backends.broadcast_shapes(shapes, backend)
        except ValueError as err:
            raise ValueError(f"{self.name}.{what}: batch shapes {shapes} do not broadcast") from err
        self._check_speed(conv.get("qdot"), what)
        fn = _function(self.definition, what, backend)
        z = backends.zeros(batch, backend, dtype)
        return fn(conv.get("q"), conv.get("qdot"), conv.get("qddot"), conv.get("tau"), params, z)

    def _check_speed(self, qdot, what: str) -> None:
        c = self.definition.max_speed
        if c is None or qdot is None or not backends.is_concrete(qdot):
            return
        if backends.max_abs(qdot) >= c:
            raise ValueError(f"{self.name}.{what}: every |qdot| must be < {c} (speed of light); got one >= {c}")

    def acceleration(self, q, qdot, backend: str = "numpy", tau=None, **overrides):
        """qddot (..., dof) from the Euler–Lagrange equations, with optional generalised forces tau."""
        if tau is None:
            return self._call("acceleration", backend, {"q": q, "qdot": qdot}, overrides)
        return self._call("acceleration_tau", backend, {"q": q, "qdot": qdot, "tau": tau}, overrides)

    def energy(self, q, qdot, backend: str = "numpy", **overrides):
        """E = qdot . dL/dqdot - L, shape (...,)."""
        return self._call("energy", backend, {"q": q, "qdot": qdot}, overrides)

    def canonical_momentum(self, q, qdot, backend: str = "numpy", **overrides):
        """p = dL/dqdot, shape (..., dof)."""
        return self._call("momentum", backend, {"q": q, "qdot": qdot}, overrides)

    def canonical_momentum_rate(self, q, qdot, backend: str = "numpy", **overrides):
        """dp/dt = dL/dq + Q along the unforced motion, shape (..., dof)."""
        return self._call("momentum_rate", backend, {"q": q, "qdot": qdot}, overrides)

    def velocity_hessian(self, q, qdot, backend: str = "numpy", **overrides):
        """d2L/dqdot2, shape (..., dof, dof); defined for every system."""
        return self._call("velocity_hessian", backend, {"q": q, "qdot": qdot}, overrides)

    def mass_matrix(self, q, backend: str = "numpy", **overrides):
        """M(q), shape (..., dof, dof); NotQuadraticError where L is not qdot^T M qdot/2 - V."""
        return self._call("mass_matrix", backend, {"q": q}, overrides)

    def gravity(self, q, backend: str = "numpy", **overrides):
        """g(q) = dV/dq, shape (..., dof)."""
        return self._call("gravity", backend, {"q": q}, overrides)

    def coriolis(self, q, qdot, backend: str = "numpy", **overrides):
        """c(q, qdot) with M qddot + c + g = tau + friction forces, shape (..., dof)."""
        return self._call("coriolis", backend, {"q": q, "qdot": qdot}, overrides)

    def coriolis_matrix(self, q, qdot, backend: str = "numpy", **overrides):
        """Christoffel-form C(q, qdot) with C qdot = c and dM/dt - 2C skew-symmetric, (..., dof, dof)."""
        return self._call("coriolis_matrix", backend, {"q": q, "qdot": qdot}, overrides)

    def inverse_dynamics(self, q, qdot, qddot, backend: str = "numpy", **overrides):
        """tau (..., dof) such that acceleration(q, qdot, tau=tau) == qddot."""
        arrays = {"q": q, "qdot": qdot, "qddot": qddot}
        return self._call("inverse_dynamics", backend, arrays, overrides)

    def sample_states(self, n: int, rng=None, distribution: str = "default") -> dict:
        """n i.i.d. states from the system's default (or a named) distribution: float64 NumPy
        arrays "q", "qdot" (n, dof) and any per-sample parameters (n,)."""
        if not isinstance(rng, np.random.Generator):
            rng = np.random.default_rng(rng)
        n = int(n)
        if n < 0:
            raise ValueError("n must be >= 0")
        out = self.definition.sampler(n, rng, self.params, distribution)
        return {k: np.asarray(v, dtype=np.float64) for k, v in out.items()}


__all__ = ["System", "NotQuadraticError", "structure_of", "source_of"]
