"""Shared fixtures for every test: the default cache is kept per session in a temp dir
unless LAGBENCH_CACHE is set (tox sets it), so repeated runs reuse generated code."""

import os

import pytest


@pytest.fixture(scope="session", autouse=True)
def _cache_dir(tmp_path_factory):
    if not os.environ.get("LAGBENCH_CACHE"):
        os.environ["LAGBENCH_CACHE"] = str(tmp_path_factory.mktemp("lagbench-cache"))
    yield
