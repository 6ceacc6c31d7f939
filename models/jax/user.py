"""A user's equinox module as a suite model (`models.user`): its inexact array leaves are the suite's parameter
dict (`models.jax.base.Model`, keyed by tree path), put back into the module's skeleton (`eqx.combine`) at
every call, so training, members, checkpoints and evaluation treat it like any other kind. A module that
declares `returns = "lagrangian"` gives a scalar L per sample, turned into q-double-dot by the suite's
Euler-Lagrange step (`models.jax.lnn.euler_lagrange`); `returns = "hamiltonian"` a scalar H(q, p), whose
time derivative is Hamilton's equations."""
from __future__ import annotations

from functools import lru_cache

import equinox as eqx
import jax
import jax.numpy as jnp

from lagbench.models import user
from lagbench.models.jax.base import Model
from lagbench.models.jax.lnn import euler_lagrange


@lru_cache(maxsize=16)
def skeleton(spec):
    """(parameter names in leaf order, the arrays' treedef, the module's non-array part) of spec's factory."""
    module = user.make_module(spec)
    if not callable(module):
        raise user._boundary().wrong(user.OPTION, spec.own.factory, "the equinox module is not callable as module(q, qdot)")
    arrays, static = eqx.partition(module, eqx.is_inexact_array)
    paths, treedef = jax.tree_util.tree_flatten_with_path(arrays)
    return tuple(jax.tree_util.keystr(p) for p, _ in paths), treedef, static


class UserModel(Model):
    def _module(self):
        names, treedef, static = skeleton(self.spec)
        return eqx.combine(jax.tree_util.tree_unflatten(treedef, [self.params[n] for n in names]), static)

    def acceleration(self, q, qdot, extra=None):
        self._check_state(q, qdot, extra)
        module = self._module()
        if user.returns(module) == "lagrangian":
            return euler_lagrange(lambda a, b: user.scalar(self.spec, user.forward(self.spec, module, module, a, b), a),
                                  q, qdot)
        out = user.forward(self.spec, module, module, q, qdot)
        user.check_output(self.spec, out, q)
        return out

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration, 0): no fallback exists."""
        return self.acceleration(q, qdot, extra), jnp.zeros((), dtype=jnp.int64)

    def time_derivative(self, x, y, extra=None):
        """A Hamiltonian module's (xdot, ydot) = (dH/dy, -dH/dx), H = module(x, y) (...,): Hamilton's equations."""
        self._check_state(x, y, extra)
        module = self._module()
        if user.returns(module) != "hamiltonian":
            raise ValueError(f"--add-model {self.spec.own.factory}: time_derivative is for a module that returns a "
                             f"Hamiltonian (returns = 'hamiltonian')")
        h = lambda a, b: jnp.sum(user.scalar(self.spec, user.forward(self.spec, module, module, a, b), a))  # noqa: E731
        dh_dx, dh_dy = jax.grad(h, argnums=(0, 1))(x, y)
        return dh_dy, -dh_dx
