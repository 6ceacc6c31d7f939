"""The speed study's evaluators and the suite's NumPy view of a model (`replication.evaluation.adapters`) are
one view: the evaluator's model is the adapter's build, and its q-double-dot (the program it times) gives the
adapter's `qddot`, for every double-pendulum kind (the HNN through its time derivative) in both frameworks."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.models import init_params
from lagbench.replication.evaluation.adapters import adapter
from lagbench.speedstudy.evaluators import make_evaluator
from lagbench.speedstudy.inference import model_spec


@pytest.mark.parametrize("framework", ["jax", "torch"])
@pytest.mark.parametrize("kind,formulation", [("lnn", "fast"), ("hnn", "-"), ("delan", "-"), ("baseline", "-")])
def test_evaluator_is_the_adapters_qddot(framework, kind, formulation):
    spec = model_spec(kind, formulation, 2, (16, 16), "float64")
    params = init_params(spec, seed=0)
    st = systems.get("double_pendulum").sample_states(12, np.random.default_rng(0))
    ev = make_evaluator(framework, spec, params)
    view = adapter(framework, spec, params)
    assert type(ev.model) is type(view.model)
    got = ev.numpy(ev.prepare(st["q"], st["qdot"]))
    want = view.qddot(st["q"], st["qdot"])
    assert got.shape == want.shape == (12, 2) and got.dtype == want.dtype == np.float64
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
