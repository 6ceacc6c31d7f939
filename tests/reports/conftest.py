"""Fixtures: hand-made result files (see result_fixtures.py) and one report built from them per session."""

from __future__ import annotations

from pathlib import Path

import pytest
from result_fixtures import write_results


@pytest.fixture(scope="session")
def results_dir(tmp_path_factory) -> Path:
    return write_results(tmp_path_factory.mktemp("results"))


@pytest.fixture(scope="session")
def small_results_dir(tmp_path_factory) -> Path:
    """Two claims' results: for the tests of what the tool does with its folders, which any report shows."""
    return write_results(tmp_path_factory.mktemp("small_results"), only=("dp_loss", "dp_energy"))


@pytest.fixture(scope="session")
def built(results_dir, tmp_path_factory) -> dict:
    from lagbench.reports import build_report

    out = tmp_path_factory.mktemp("report")
    return build_report(results_dir, out)
