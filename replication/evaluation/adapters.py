"""NumPy views of a trained model in either framework, for evaluation.

`adapter(framework, spec, params)` returns an object with the model's public methods
(`acceleration`, `time_derivative`, `inverse_dynamics`, `mass_matrix`, `coriolis`, `gravity`,
`acceleration_info`, ...) taking and returning float64 NumPy arrays. Inputs are cast to the
model's dtype; large batches are evaluated in chunks. JAX methods are jit-compiled once per method.
So evaluation code (metrics, rollouts) is written once and judges both frameworks alike.
`view.model` is the framework's model object (`lagbench.models.jax.build` / `lagbench.models.torch.build`).

`qddot(model, kind, q, qdot)`: q-double-dot of any model kind, on a framework model or on a view: the
acceleration, or for an HNN ("hnn") the second half of its time derivative on the non-canonical (q, qdot);
`view.qddot(q, qdot)` is it in NumPy, (B, d) float64. The speed study's evaluators (`speedstudy.evaluators`)
build their models here and time this same `qddot`.
"""
from __future__ import annotations

import numpy as np

CHUNK = 32768   # one chunk (one compiled shape) for every quick held-out set; 4 at paper scale
SMALLEST = 16   # padded batches: a power of two >= this, so a JIT compiles a few shapes, not one per size


def padded_size(n: int) -> int:
    """The batch size n rows are padded to (`fit.load.Padded`, `rollout_native`): a power of two >= SMALLEST."""
    return max(SMALLEST, 1 << max(n - 1, 0).bit_length())


def qddot(model, kind: str, q, qdot):
    """q-double-dot (B, d) of `model` (a framework model or a view) of model kind `kind`."""
    if kind == "hnn":
        return model.time_derivative(q, qdot)[1]
    return model.acceleration(q, qdot)


class _Adapter:
    def __init__(self, spec, params):
        self.spec = spec
        self.kind = spec.kind
        self._fns = {}

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        if name not in self._fns:
            self._fns[name] = self._compile(name)
        fn = self._fns[name]

        def call(*args):
            args = [None if a is None else np.asarray(a, np.float64) for a in args]
            n = next(a.shape[0] for a in args if a is not None)
            outs = [fn(*[None if a is None else a[i:i + CHUNK] for a in args]) for i in range(0, max(n, 1), CHUNK)]
            if isinstance(outs[0], tuple):
                return tuple(_join([o[j] for o in outs]) for j in range(len(outs[0])))
            return _join(outs)
        return call

    def qddot(self, q, qdot):
        return qddot(self, self.kind, q, qdot)


def _join(parts):
    parts = [np.asarray(p, dtype=np.float64) for p in parts]
    if parts[0].ndim == 0:
        return np.sum(parts)
    return np.concatenate(parts, axis=0)


_JITTED: dict = {}


def _jitted(name: str):
    """One compiled call of the model method `name` per process: equinox caches it by the model's structure,
    so adapters of many parameter sets of one spec (seeds, held-out checks during training) compile once."""
    if name not in _JITTED:
        import equinox as eqx

        _JITTED[name] = eqx.filter_jit(lambda m, *a: getattr(m, name)(*a))
    return _JITTED[name]


class JaxAdapter(_Adapter):
    def __init__(self, spec, params):
        super().__init__(spec, params)
        import jax.numpy as jnp

        import lagbench.models.jax

        self._jnp = jnp
        self.model = lagbench.models.jax.build(spec, params)

    def _compile(self, name):
        jnp, dtype = self._jnp, self._jnp.dtype(self.spec.dtype)
        f = _jitted(name)

        def run(*args):
            a = [None if x is None else jnp.asarray(x, dtype) for x in args]
            out = f(self.model, *a)
            return tuple(np.asarray(o) for o in out) if isinstance(out, tuple) else np.asarray(out)
        return run


class TorchAdapter(_Adapter):
    def __init__(self, spec, params):
        super().__init__(spec, params)
        import torch

        import lagbench.models.torch

        self._torch = torch
        self.model = lagbench.models.torch.build(spec, params)

    def _compile(self, name):
        torch, dtype = self._torch, getattr(self._torch, self.spec.dtype)
        method = getattr(self.model, name)

        def run(*args):
            a = [None if x is None else torch.as_tensor(x, dtype=dtype) for x in args]
            with torch.no_grad():
                out = method(*a)
            conv = lambda o: o.detach().cpu().numpy() if hasattr(o, "detach") else np.asarray(o)  # noqa: E731
            return tuple(conv(o) for o in out) if isinstance(out, tuple) else conv(out)
        return run


def adapter(framework: str, spec, params):
    if framework == "jax":
        return JaxAdapter(spec, params)
    if framework == "torch":
        return TorchAdapter(spec, params)
    raise ValueError(f"unknown framework {framework!r}; valid: jax, torch")
