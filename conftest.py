"""Shared fixtures for every test: the default cache is kept per session in a temp dir
unless LAGBENCH_CACHE is set (tox sets it), so repeated runs reuse generated code."""

import json
import os
import shutil
import tempfile
from pathlib import Path

import pytest

from lagbench.replication.run import jax_cache
from lagbench.replication.run.environment import one_thread_env

# Under pytest-xdist the workers share the machine's cores, so each computes on one thread (JAX's XLA,
# PyTorch, OpenMP, MKL), as the replication's own worker processes do. Set here, before any test module
# imports JAX or PyTorch; a test that needs other threads sets them itself.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.update(one_thread_env(os.environ))

# The tests' JAX programs are mostly small and run briefly, so compiling them is most of their time: XLA
# compiles them without LLVM's optimisation passes (a quarter less time for the smoke run's JAX claims; the few
# tests that compute for long run slower, and the whole run is still 16 % faster: docs/lab/test_suite_time.md).
# The numbers agree with the optimised programs' to rounding, which every tolerance in the suite allows. Runs
# outside the tests compile as XLA does by default; LAGBENCH_TEST_OPTIMISED_XLA=1 tests the optimised programs.
TEST_XLA = "--xla_backend_optimization_level=0"
if not os.environ.get("LAGBENCH_TEST_OPTIMISED_XLA") and TEST_XLA not in os.environ.get("XLA_FLAGS", ""):
    os.environ["XLA_FLAGS"] = f"{os.environ.get('XLA_FLAGS', '')} {TEST_XLA}".strip()

# JAX keeps its compiled programs for the test run in one temporary folder, shared by both workers and by every
# process a test starts (the CLI, the run's worker processes): a program compiled again by another test, worker
# or resumed run is read back instead (a sixth less time for the model and training tests:
# docs/lab/test_suite_time.md). The folder is made empty by the process that starts the run and removed when the
# run ends, so no test reads a compilation from another run.
_OWN_JAX_CACHE = None
if not os.environ.get("JAX_COMPILATION_CACHE_DIR"):
    _OWN_JAX_CACHE = tempfile.mkdtemp(prefix="lagbench-tests-jax-")
    os.environ["JAX_COMPILATION_CACHE_DIR"] = _OWN_JAX_CACHE
    # as `lagbench` sets them: its size limit also turns on JAX's file lock, so that no process reads an entry
    # another is still writing (JAX would warn, and the tests turn warnings into errors)
    os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", str(jax_cache.MIN_COMPILE_S))
    os.environ.setdefault("JAX_COMPILATION_CACHE_MAX_SIZE", str(jax_cache.MAX_BYTES))


def pytest_unconfigure(config):
    if _OWN_JAX_CACHE:
        shutil.rmtree(_OWN_JAX_CACHE, ignore_errors=True)


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


GROUP_SECONDS = Path(__file__).parent / "tests" / "timing" / "group_seconds.json"


def group_seconds() -> dict:
    """The measured seconds of each worker group (`tests/timing/group_seconds.py` makes the table); {} where the
    table is missing or unreadable (the run then keeps pytest's order)."""
    try:
        table = json.loads(GROUP_SECONDS.read_text())
    except (OSError, ValueError):
        return {}
    return {str(g): float(s) for g, s in table.items()} if isinstance(table, dict) else {}


def longest_first(groups, seconds: dict) -> list:
    """`groups` ordered by their measured seconds, longest first (a group not measured counts as the median of
    those measured): handed out so, the last groups a worker takes are short, and the two workers end together."""
    known = sorted(seconds.values())
    default = known[len(known) // 2] if known else 0.0
    return sorted(groups, key=lambda g: -seconds.get(g, default))


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    from xdist.scheduler import LoadScopeScheduling

    class ByWorkerGroup(LoadScopeScheduling):
        """Groups whole on one worker, handed out longest first by `tests/timing/group_seconds.json`."""

        ordered = False

        def _split_scope(self, nodeid: str) -> str:
            return worker_group(nodeid)

        def _assign_work_unit(self, node) -> None:
            if not self.ordered:   # the queue is whole at the first assignment
                queue = dict(self.workqueue)
                self.workqueue.clear()
                for group in longest_first(queue, group_seconds()):
                    self.workqueue[group] = queue[group]
                self.ordered = True
            super()._assign_work_unit(node)

    return ByWorkerGroup(config, log)
