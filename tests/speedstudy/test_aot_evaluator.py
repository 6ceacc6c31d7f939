"""speedstudy.evaluators.TorchAotEvaluator on the SymPy ground truth: one library, exported with a
dynamic batch (the truth's batch shape comes from `systems.backends.broadcast_shapes`, which keeps
torch's symbolic sizes), gives the NumPy truth's numbers (float64) at batch sizes other than the traced
one. One small compile per timed thread count (pendulum, one degree of freedom)."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.speedstudy.evaluators import TorchAotEvaluator, make_evaluator


@pytest.mark.slow   # slow: a speed-study compile path (`lagbench bench`'s quick preset); the paths verdicts use stay in the default run
def test_truth_any_batch_matches_numpy():
    s = systems.get("pendulum")
    ev = make_evaluator("torch", kind="truth", dtype="float64", system=s, mode="aoti")
    assert isinstance(ev, TorchAotEvaluator) and ev.mode == "aoti"
    assert ev._libs and all(lib.in_shape == (None, 1) for lib in ev._libs.values())  # one per thread count
    rng = np.random.default_rng(0)
    for b in (1, 3, 40):
        st = s.sample_states(b, rng)
        got = ev.numpy(ev.prepare(st["q"], st["qdot"]))
        np.testing.assert_allclose(got, s.acceleration(st["q"], st["qdot"], backend="numpy"), rtol=1e-12,
                                   atol=1e-12)
