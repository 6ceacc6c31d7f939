"""`lagbench evaluate --predict` over a slow function (issue 85, item 3): a progress bar over every call the
scoring makes, and a per-call limit (`--call-limit`) that stops the scoring with one line."""
import time

import pytest

from lagbench.cli import main
from lagbench.replication.predictor.score import calls_of, score, setup

FUNCTIONS = '''
import time

import numpy as np

calls = []


def zero(q, qdot):
    return np.zeros_like(q)


def stuck(q, qdot):
    time.sleep(30)
    return np.zeros_like(q)


def swallowing(q, qdot):   # a broad `except Exception` does not keep the limit from stopping it
    try:
        time.sleep(30)
    except Exception:
        pass
    return np.zeros_like(q)


def slower(q, qdot):   # fast twice, then stuck
    calls.append(1)
    if len(calls) > 2:
        time.sleep(30)
    return np.zeros_like(q)
'''


@pytest.fixture
def functions(tmp_path):
    path = tmp_path / "mine.py"
    path.write_text(FUNCTIONS)
    return path


def _predict(functions, tmp_path, name, *args):
    return main(["evaluate", "--predict", f"{functions}:{name}", "--system", "double_pendulum", "--profile", "smoke",
                 "--out", str(tmp_path / "out"), *args])


def test_every_call_is_counted_against_the_total_the_scoring_makes():
    import numpy as np

    seen = []
    score(lambda q, qd: np.zeros_like(q), "double_pendulum", "smoke", on_call=lambda done, total: seen.append((done, total)))
    total = calls_of(setup("double_pendulum", "smoke"))
    assert total > 100 and seen == [(k, total) for k in range(1, total + 1)]


def test_the_command_shows_a_progress_bar_over_the_calls(functions, tmp_path, capsys):
    assert _predict(functions, tmp_path, "zero") in (0, None)
    err = capsys.readouterr().err
    total = calls_of(setup("double_pendulum", "smoke"))
    assert f"lagbench evaluate --predict {functions}:zero" in err and f"{total}/{total}" in err and "call/s" in err, err
    assert _predict(functions, tmp_path, "zero", "--quiet") in (0, None)
    assert "call/s" not in capsys.readouterr().err


@pytest.mark.parametrize("name, call", [("stuck", "call 1)"), ("swallowing", "call 1)"),
                                        ("slower", "call 3; the 2 before it took")])
def test_a_call_past_the_limit_stops_the_scoring_with_one_line(functions, tmp_path, capsys, name, call):
    t0 = time.perf_counter()
    assert _predict(functions, tmp_path, name, "--call-limit", "0.2", "--quiet") == 2
    assert time.perf_counter() - t0 < 20   # the stuck call is interrupted, never waited out
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{name}(q, qdot)" in err and "ran past --call-limit 0.2 s" in err, err
    assert call in err and "Traceback" not in err
    assert not (tmp_path / "out" / "predict" / "double_pendulum" / name / "result.json").exists()


@pytest.mark.parametrize("args, words", [(["--call-limit", "0"], "--call-limit: 0.0 is not valid"),
                                         (["--call-limit", "nan"], "--call-limit: nan is not valid")])
def test_a_bad_limit_is_one_line(functions, tmp_path, capsys, args, words):
    assert _predict(functions, tmp_path, "zero", *args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err, err


def test_the_limit_is_for_predict_only(tmp_path, capsys):
    assert main(["evaluate", "--fitted", str(tmp_path), "--data", "d.csv", "--call-limit", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--call-limit: with --predict only" in err, err
