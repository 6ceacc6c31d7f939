"""One smoke run shared by the replication and integration tests.

The claims that tests compare across frameworks (`BOTH`), and any claim `ONE_FRAMEWORK` does not list, run in JAX
and in PyTorch; the claims it lists run in one framework (`ONE_FRAMEWORK`), about half of them in each, so that each framework's whole path (training,
evaluation, judging, result files) is exercised while each claim is compiled and trained once. The per-step
agreement of the frameworks is the parity tests' (`tests/replication/training/test_training_parity.py`);
`tox -e slow` runs every claim in both frameworks (`test_smoke.py`).
"""
import pytest

from lagbench.replication.run import runner

BOTH = ("appendix_b",)
ONE_FRAMEWORK = {"dp_loss": "jax", "dp_energy": "jax",   # one training chain (claim 2 rolls out claim 1's models)
                 "rel_coords": "jax", "init_study": "jax", "delan_table1": "jax", "precision": "jax",
                 "delan_online": "jax",
                 "wave_lgn": "torch", "activation_study": "torch", "hnn_energy": "torch", "delan_arm": "torch",
                 "delan_tracking": "torch"}   # claim 12 tracks with claim 9's arm trainings: one framework for both


def frameworks_of(cid: str) -> set:
    """The frameworks the session's smoke run runs claim `cid` in."""
    return {ONE_FRAMEWORK[cid]} if cid in ONE_FRAMEWORK else {"jax", "torch"}


def smoke_plan(plan):
    """`runner.plan` with each claim kept to `frameworks_of` it."""
    def planned(*args, **kwargs):
        return [u for u in plan(*args, **kwargs) if u.framework in frameworks_of(u.claim.id)]
    return planned


@pytest.fixture(scope="session")
def smoke_results(tmp_path_factory):
    out = tmp_path_factory.mktemp("smoke")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(runner, "plan", smoke_plan(runner.plan))
        summary = runner.run(profile="smoke", out=out, progress=False)
    return out, summary


@pytest.fixture(scope="session")
def smoke_frameworks():
    """`frameworks_of`, for the tests that read the session's smoke run."""
    return frameworks_of
