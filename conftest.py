"""Shared fixtures for every test: the default cache is kept per session in a temp dir
unless LAGBENCH_CACHE is set (tox sets it), so repeated runs reuse generated code."""

import os

import pytest

from replication.run.environment import one_thread_env

# Under pytest-xdist the workers share the machine's cores, so each computes on one thread (JAX's XLA,
# PyTorch, OpenMP, MKL), as the replication's own worker processes do. Set here, before any test module
# imports JAX or PyTorch; a test that needs other threads sets them itself.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.update(one_thread_env(os.environ))

# The tests compile the same JAX programs many times over (the smoke run, then its reruns, resumptions and
# the command line's subprocesses), so under tox (which sets LAGBENCH_CACHE) they share JAX's persistent
# compilation cache in a folder of that cache: a program compiled once in any test process is read back in
# the others. A size limit turns on JAX's file lock, as the two workers and their subprocesses read and write
# it at once. Compiled code gives the numbers a fresh compilation gives; nothing here changes a tested value.
# Set before any test module imports JAX (its configuration reads these at import); subprocesses inherit them.
if os.environ.get("LAGBENCH_CACHE") and "JAX_COMPILATION_CACHE_DIR" not in os.environ:
    os.environ.update({"JAX_COMPILATION_CACHE_DIR": os.path.join(os.environ["LAGBENCH_CACHE"], "jax-tests"),
                       "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0",
                       "JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES": "0",
                       "JAX_COMPILATION_CACHE_MAX_SIZE": str(4 * 2**30)})


@pytest.fixture(scope="session", autouse=True)
def _cache_dir(tmp_path_factory):
    if not os.environ.get("LAGBENCH_CACHE"):
        os.environ["LAGBENCH_CACHE"] = str(tmp_path_factory.mktemp("lagbench-cache"))
    yield


# Under pytest-xdist (`tox` runs `pytest -n 2`), tests go to the workers in groups, each run whole on one
# worker (`pytest_xdist_make_scheduler`): a test file's tests together, so that its module fixtures are built
# once, and the files that use one expensive session fixture together, so that it is built once, not once
# per worker. A test file that starts using one of these fixtures is listed here;
# `tests/test_worker_groups.py` fails until it is.
SHARED_SESSION_FIXTURES = {
    "smoke_results": ("tests/replication/run/test_executor.py", "tests/replication/run/test_resume.py",
                      "tests/replication/run/test_smoke.py", "tests/replication/training/test_hard_cases.py"),
    "bench_dir": ("tests/speedstudy/test_bench_resume.py", "tests/speedstudy/test_speed_study.py"),
}
WORKER_GROUP = {path: fixture for fixture, paths in SHARED_SESSION_FIXTURES.items() for path in paths}


def worker_group(nodeid: str) -> str:
    """The group a test runs in: its session fixture's, or its file's."""
    path = nodeid.split("::", 1)[0]
    return WORKER_GROUP.get(path, path)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    from xdist.scheduler import LoadScopeScheduling

    class ByWorkerGroup(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return worker_group(nodeid)

    return ByWorkerGroup(config, log)
