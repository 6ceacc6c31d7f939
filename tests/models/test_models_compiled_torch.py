"""models.torch.compiled.compile_single (torch.export + AOTInductor): the compiled library gives the model
method's numbers (float64), for contiguous and strided inputs alike, and refuses inputs of another shape or dtype with a message naming them.
Compiling takes 15-40 s, so the default run compiles once; the batched/tau case is marked slow."""
import numpy as np
import pytest
import torch

import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.torch.compiled import compile_single

RNG = np.random.default_rng(0)


def _model(**kw):
    spec = ModelSpec(kind="delan", dof=2, hidden=(16, 16), dtype="float64", init="xavier", **kw)
    return lagbench.models.torch.build(spec, init_params(spec, seed=1))


@pytest.mark.slow   # slow: a speed-study compile path (`lagbench bench`'s quick preset); the paths verdicts use stay in the default run
def test_delan_inverse_dynamics_matches_method_and_checks_inputs():
    m = _model()
    f = compile_single(m, "inverse_dynamics")
    for _ in range(3):
        xs = [torch.tensor(RNG.uniform(-2, 2, 2)) for _ in range(3)]
        with torch.no_grad():
            want = m.inverse_dynamics(*xs)
        got = f(*xs)
        assert got.shape == want.shape
        np.testing.assert_allclose(got.numpy(), want.numpy(), rtol=0, atol=1e-12)
    strided = torch.tensor(RNG.uniform(-2, 2, (3, 4)))[:, ::2]  # views that are not contiguous
    with torch.no_grad():
        want = m.inverse_dynamics(*strided)
    np.testing.assert_allclose(f(*strided).numpy(), want.numpy(), rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"input 0: compiled for a \(2,\) torch.float64"):
        f(torch.zeros(3, dtype=torch.float64), *xs[1:])
    with pytest.raises(ValueError, match="input 1.*float32"):
        f(xs[0], xs[1].float(), xs[2])
    with pytest.raises(ValueError, match="3 inputs, got 2"):
        f(*xs[:2])
    with pytest.raises(ValueError, match="no method 'fly'"):
        compile_single(m, "fly")


@pytest.mark.slow
def test_batched_acceleration_with_tau():
    m = _model()
    f = compile_single(m, "acceleration", batch=5, n_inputs=3)
    xs = [torch.tensor(RNG.uniform(-1, 1, (5, 2))) for _ in range(3)]
    with torch.no_grad():
        want = m.acceleration(*xs)
    np.testing.assert_allclose(f(*xs).numpy(), want.numpy(), rtol=0, atol=1e-12)
