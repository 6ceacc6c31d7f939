"""replication.bench.evaluators.TorchAotEvaluator on the SymPy ground truth, whose generated PyTorch code
fixes the batch size while torch.export traces it: the evaluator falls back to one library per batch
size and gives the NumPy truth's numbers (float64). Two small compiles (pendulum, one degree of
freedom), about 15 s."""
import numpy as np

import systems
from replication.bench.evaluators import TorchAotEvaluator, make_evaluator


def test_truth_per_batch_fallback_matches_numpy():
    s = systems.get("pendulum")
    ev = make_evaluator("torch", kind="truth", dtype="float64", system=s, mode="aoti")
    assert isinstance(ev, TorchAotEvaluator) and ev.mode == "aoti" and ev._any is None  # per batch size
    rng = np.random.default_rng(0)
    for b in (1, 3):
        st = s.sample_states(b, rng)
        got = ev.numpy(ev.prepare(st["q"], st["qdot"]))
        np.testing.assert_allclose(got, s.acceleration(st["q"], st["qdot"], backend="numpy"), rtol=1e-12,
                                   atol=1e-12)
    assert sorted(ev._per_batch) == [1, 3]
