"""Members trained as one program (stacked parameters, one vmapped step) against the one-at-a-time loop:
in float64 every member's loss, gradient norm and skipped-step count agree at every step, and its final
weights too, in both frameworks; a member that fails stops alone. (JAX against PyTorch for members: the
`lnn_members` row of `test_training_parity`, whose spec, protocol, seeds and compiled steps these share.)"""
import numpy as np
import pytest
from parity_kit import Recorder
from parity_rows import BY_NAME

from lagbench.models import init_params
from lagbench.replication.training.data import BatchStream

# the guard on and tight (clip below the norms, skip at the median): members clip and skip on different steps
ROW = BY_NAME["lnn_members"]
SPEC, PROTOCOL, SEEDS = ROW.spec, ROW.protocol, ROW.seeds
FRAMEWORKS = ("jax", "torch")


def _alone(fw, seed, protocol=PROTOCOL, spec=SPEC):
    return Recorder(fw).train(spec, init_params(spec, seed=seed), protocol, BatchStream(protocol, seed))


def _together(fw, protocol=PROTOCOL, params=None, spec=SPEC, seeds=SEEDS):
    params = params or [init_params(spec, seed=s) for s in seeds]
    return Recorder(fw).train_members(spec, params, protocol, [BatchStream(protocol, s) for s in seeds])


@pytest.mark.parametrize("fw", sorted(FRAMEWORKS))
def test_every_member_equals_its_own_run(fw):
    together = _together(fw)
    skipped = set()
    for seed, b in zip(SEEDS, together, strict=True):
        a = _alone(fw, seed)
        assert a.failure is None and b.failure is None and len(a.log) == len(b.log) == PROTOCOL.steps
        for ra, rb in zip(a.log, b.log, strict=True):
            assert ra["step"] == rb["step"] and ra["lr"] == rb["lr"]
            np.testing.assert_allclose(rb["loss"], ra["loss"], rtol=1e-10, err_msg=f"seed {seed} step {ra['step']}")
            np.testing.assert_allclose(rb["grad_norm"], ra["grad_norm"], rtol=1e-10,
                                       err_msg=f"seed {seed} step {ra['step']}")
            assert ra["skipped_steps"] == rb["skipped_steps"], f"seed {seed} step {ra['step']}"
        for k in a.params:
            np.testing.assert_allclose(b.params[k], a.params[k], rtol=1e-9, atol=1e-12, err_msg=f"seed {seed} {k}")
        skipped.add(b.skipped_steps)
    assert len(skipped) > 1, "the members should skip different numbers of steps, or the test shows little"


@pytest.mark.parametrize("fw", sorted(FRAMEWORKS))
@pytest.mark.parametrize("name", ["lgn_banded", "baseline_dp", "baseline_invdyn", "lnn_l1_gamma"])
def test_other_kinds_as_members_equal_their_own_runs(fw, name):
    """The banded LGN under vmap (its out-of-place tangents, its implicit banded solve, its fallback with no
    branch on data: what `Protocol.scouting` runs for the wave claim); and the other kinds and losses that
    PyTorch stacks without vmap (`models.torch.stacks`): the baseline (relu, and the inverse-dynamics map
    with extra inputs under MSE) and the LNN with extra inputs under the relativistic weighted L1."""
    row = BY_NAME[name]
    spec, protocol, seeds = row.spec, row.protocol.replace(steps=6), (0, 1, 2)
    for seed, b in zip(seeds, _together(fw, protocol, spec=spec, seeds=seeds), strict=True):
        a = _alone(fw, seed, protocol, spec)
        assert a.failure is None and b.failure is None and len(a.log) == len(b.log) == protocol.steps
        for ra, rb in zip(a.log, b.log, strict=True):
            np.testing.assert_allclose(rb["loss"], ra["loss"], rtol=1e-10, err_msg=f"seed {seed} step {ra['step']}")
        for k in a.params:
            np.testing.assert_allclose(b.params[k], a.params[k], rtol=1e-9, atol=1e-12, err_msg=f"seed {seed} {k}")


@pytest.mark.parametrize("fw", sorted(FRAMEWORKS))
def test_a_failed_member_stops_alone(fw):
    """A member whose weights are NaN fails at step 0 with its parameters kept; the others train on."""
    params = [init_params(SPEC, seed=s) for s in SEEDS]
    params[1] = {k: np.full_like(v, np.nan) for k, v in params[1].items()}
    protocol = PROTOCOL.replace(steps=5)
    out = _together(fw, protocol, params)
    assert out[1].failure is not None and out[1].failure["step"] == 0 and out[1].steps_done == 0
    assert all(np.isnan(v).all() for v in out[1].params.values())
    for i in (0, 2, 3):
        alone = _alone(fw, SEEDS[i], protocol)
        assert out[i].failure is None and out[i].steps_done == 5
        for k in alone.params:
            np.testing.assert_allclose(out[i].params[k], alone.params[k], rtol=1e-9, atol=1e-12)
