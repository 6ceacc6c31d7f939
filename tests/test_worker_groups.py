"""The test run's worker groups (the root conftest.py): every test that uses an expensive session fixture
runs in that fixture's group, so under pytest-xdist the fixture is built on one worker only."""
from pathlib import Path


def _root_conftest(config):
    return config.pluginmanager.get_plugin(str(Path(config.rootpath, "conftest.py")))


def test_every_user_of_a_shared_session_fixture_is_in_its_group(request):
    root = _root_conftest(request.config)
    for item in request.session.items:   # the whole run's tests (every worker collects them all)
        for fixture in root.SHARED_SESSION_FIXTURES:
            if fixture in item.fixturenames:
                assert root.worker_group(item.nodeid) == fixture, (
                    f"{item.nodeid} uses {fixture}: list its file under SHARED_SESSION_FIXTURES in conftest.py")


def test_other_tests_group_by_file_and_the_listed_files_exist(request):
    root = _root_conftest(request.config)
    assert root.worker_group("tests/models/test_models_lnn.py::test_x[a-b]") == "tests/models/test_models_lnn.py"
    assert root.worker_group("tests/replication/run/test_smoke.py::test_y") == "smoke_results"
    assert root.worker_group("tests/speedstudy/test_speed_study.py::T::test_z") == "bench_dir"
    for paths in root.SHARED_SESSION_FIXTURES.values():
        assert all(Path(request.config.rootpath, p).is_file() for p in paths), paths


def test_groups_are_handed_out_longest_first_and_an_unmeasured_one_as_the_median(request):
    root = _root_conftest(request.config)
    seconds = {"a": 40.0, "b": 5.0, "c": 90.0, "d": 20.0, "e": 30.0}   # median 30
    assert root.longest_first(["b", "new", "a", "c", "d"], seconds) == ["c", "a", "new", "d", "b"]
    assert root.longest_first(["b", "a"], {}) == ["b", "a"]   # no table: pytest's order


def test_the_committed_timing_table_names_only_groups_that_exist(request):
    root = _root_conftest(request.config)
    table = root.group_seconds()
    assert table, f"{root.GROUP_SECONDS} is missing or unreadable: python tests/timing/group_seconds.py JUNIT_XML"
    stale = [g for g in table if g not in root.SHARED_SESSION_FIXTURES and not Path(request.config.rootpath, g).is_file()]
    assert not stale, f"{stale}: remake tests/timing/group_seconds.json (python tests/timing/group_seconds.py JUNIT_XML)"
