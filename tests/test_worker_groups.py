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
