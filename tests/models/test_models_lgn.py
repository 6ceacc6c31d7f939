"""Lagrangian graph network: the banded O(n) path equals the dense path (cyclic wrap included), for
several grid sizes and radii, in both frameworks; a model built at n = 10 runs at n = 100."""
import numpy as np
import pytest
import torch
from models_testkit import assert_rel, make_inputs, spec_params, to_jax

import models.jax
import models.torch
from models import ModelSpec


@pytest.mark.parametrize("n, r", [(5, 1), (7, 1), (10, 1), (13, 1), (9, 2), (12, 2), (100, 1)])
def test_banded_equals_dense_torch(n, r):
    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", lgn_radius=r, formulation="banded")
    x = make_inputs(spec, batch=4, seed=n, n=n)
    q, qdot = torch.tensor(x["q"]), torch.tensor(x["qdot"])
    banded, n_bad = models.torch.build(spec, params).acceleration_info(q, qdot)
    dense_spec = ModelSpec.from_dict(spec.to_dict() | {"formulation": "dense"})
    dense = models.torch.build(dense_spec, params).acceleration(q, qdot)
    assert banded.shape == (4, n) and int(n_bad) == 0
    assert_rel(banded.detach(), dense.detach(), "float64", f"banded vs dense n={n} r={r}", factor=100)


def test_banded_equals_dense_jax_and_transfers_to_a_larger_grid():
    spec, params = spec_params(kind="lgn", dof=10, dtype="float64", formulation="banded")
    model = models.jax.build(spec, params)
    dense = models.jax.build(ModelSpec.from_dict(spec.to_dict() | {"formulation": "dense"}), params)
    for n in (10, 100):
        x = to_jax(make_inputs(spec, batch=3, seed=n, n=n))
        a, n_bad = model.acceleration_info(x["q"], x["qdot"])
        assert a.shape == (3, n) and int(n_bad) == 0
        assert_rel(a, dense.acceleration(x["q"], x["qdot"]), "float64", f"jax banded vs dense n={n}", factor=100)


def test_tiny_grids_use_the_dense_path():
    spec, params = spec_params(kind="lgn", dof=3, dtype="float64", formulation="banded")
    x = make_inputs(spec, batch=2, n=3)
    a = models.torch.build(spec, params).acceleration(torch.tensor(x["q"]), torch.tensor(x["qdot"]))
    assert a.shape == (2, 3) and np.all(np.isfinite(a.detach().numpy()))
