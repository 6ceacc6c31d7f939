"""One smoke run of every claim in both frameworks, shared by the replication and integration tests."""
import pytest

from replication.run.runner import run


@pytest.fixture(scope="session")
def smoke_results(tmp_path_factory):
    out = tmp_path_factory.mktemp("smoke")
    summary = run(profile="smoke", out=out, progress=False)
    return out, summary
