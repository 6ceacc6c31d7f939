"""Shared fixtures for every test: the default cache is kept per session in a temp dir
unless LAGBENCH_CACHE is set (tox sets it), so repeated runs reuse generated code."""

import os

import pytest


@pytest.fixture(scope="session", autouse=True)
def _cache_dir(tmp_path_factory):
    if not os.environ.get("LAGBENCH_CACHE"):
        os.environ["LAGBENCH_CACHE"] = str(tmp_path_factory.mktemp("lagbench-cache"))
    yield


# Under pytest-xdist (`tox` runs `pytest -n 2 --dist loadgroup`), each group runs whole on one worker: a
# test file's tests together (its module fixtures are built once), and every user of an expensive
# session fixture in one group, so that fixture is built once, not once per worker.
SHARED_SESSION_FIXTURES = {"smoke_results": "smoke-run", "bench_dir": "tiny-bench"}


def pytest_collection_modifyitems(config, items):
    for item in items:
        used = getattr(item, "fixturenames", ())
        group = next((g for f, g in SHARED_SESSION_FIXTURES.items() if f in used), item.nodeid.split("::")[0])
        item.add_marker(pytest.mark.xdist_group(group))
