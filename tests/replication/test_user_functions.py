"""The one boundary with a user's code (`lagbench.files.user_functions`): an exception in it is one line naming the
user's file, line, function and the exception, and whether a rerun can help; its traceback is the user's; a
module loads from the user's folder first, and a name that collides with a suite package is refused."""
import sys

import numpy as np
import pytest

from lagbench.files.user_functions import (
    NO_RERUN,
    UserCodeError,
    array_of,
    call,
    import_function,
    is_users,
    nonfinite_failure,
    nonfinite_rows,
)

CODE = '''import helper_beside


def inner(x):
    return {"a": 1}[x]


def outer(x):
    return inner(x)


def oom(x):
    raise MemoryError("no room")


def seven():
    return helper_beside.SEVEN
'''


@pytest.fixture
def user_file(tmp_path):
    (tmp_path / "helper_beside.py").write_text("SEVEN = 7\n")
    path = tmp_path / "mine_code.py"
    path.write_text(CODE)
    return path


def test_an_exception_is_one_line_naming_the_file_line_function_and_that_a_rerun_cannot_help(user_file):
    fn = import_function(f"{user_file}:outer", "--predict")
    with pytest.raises(UserCodeError) as e:
        call("--predict", f"{user_file}:outer", "outer(q, qdot)", fn, "b")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"--predict {user_file}:outer: outer(q, qdot) raised KeyError: 'b'")
    assert "mine_code.py line 5, in inner" in msg and msg.endswith(NO_RERUN) and is_users(msg)
    assert not e.value.rerun and isinstance(e.value, ValueError)   # the command line's exit 2
    # the user's traceback: from their first frame on, none of the suite's
    assert e.value.details.startswith("Traceback (your code):") and "user_functions.py" not in e.value.details
    assert e.value.details.count("mine_code.py") == 2 and "KeyError: 'b'" in e.value.details


def test_running_out_of_memory_may_pass_on_a_rerun(user_file):
    fn = import_function(f"{user_file}:oom", "--predict")
    with pytest.raises(UserCodeError, match="MemoryError: no room .*a rerun may help") as e:
        call("--predict", "x:oom", "oom(q, qdot)", fn, 1)
    assert e.value.rerun and is_users(str(e.value))
    assert not is_users("dp_loss/jax/lnn/seed0: worker stopped (exit code -9); a rerun retries it")


def test_a_file_given_by_path_imports_the_modules_beside_it(user_file, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path.parent)   # not the file's folder
    assert import_function(f"{user_file}:seven", "--predict")() == 7
    assert str(user_file.parent) not in sys.path   # put first while it loads, then taken away


def test_a_module_that_raises_on_import_is_one_line(tmp_path, monkeypatch):
    (tmp_path / "broken_at_import.py").write_text("x = 1 / 0\n\ndef f():\n    pass\n")
    monkeypatch.chdir(tmp_path)
    for ref in ("broken_at_import:f", "broken_at_import.py:f"):
        with pytest.raises(UserCodeError, match=r"raised ZeroDivisionError: division by zero \(broken_at_import.py "
                                                r"line 1, in <module>\)"):
            import_function(ref, "--predict")


def test_a_users_module_named_like_a_suite_folder_is_the_users(tmp_path, monkeypatch):
    """The suite installs only `lagbench`: a user's systems.py or models/ is theirs by module name."""
    (tmp_path / "systems.py").write_text("def make(dof):\n    return 'mine'\n")
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "__init__.py").write_text("def make(dof):\n    return 'my models'\n")
    monkeypatch.chdir(tmp_path)
    assert import_function("systems:make", "--add-model")(1) == "mine"
    assert import_function("models:make", "--add-model")(1) == "my models"
    assert import_function("systems.py:make", "--add-model")(1) == "mine"


def test_a_users_file_named_like_the_suite_package_loads_from_its_path_or_is_refused(tmp_path, monkeypatch):
    (tmp_path / "lagbench.py").write_text("def make(dof):\n    return 'mine'\n")
    monkeypatch.chdir(tmp_path)
    assert import_function("lagbench.py:make", "--add-model")(1) == "mine"   # by path: the user's file
    with pytest.raises(ValueError, match="lagbench.py in the working folder has the name of the suite's package "
                                         "'lagbench'.*give its path \\(lagbench.py:make\\)"):
        import_function("lagbench:make", "--add-model")
    monkeypatch.chdir(tmp_path.parent)   # no file of that name here: the suite's own module, as named
    assert import_function("lagbench.systems:get", "--predict").__module__.startswith("lagbench.systems")


def test_a_module_of_the_working_folder_is_imported_before_an_installed_one(tmp_path, monkeypatch):
    (tmp_path / "lagbench_first_try.py").write_text("def f():\n    return 'working folder'\n")
    other = tmp_path / "elsewhere"
    other.mkdir()
    (other / "lagbench_first_try.py").write_text("def f():\n    return 'elsewhere'\n")
    monkeypatch.syspath_prepend(str(other))
    monkeypatch.setattr(sys, "path", [*sys.path, str(tmp_path)])   # the working folder on the path, but last
    monkeypatch.chdir(tmp_path)
    monkeypatch.delitem(sys.modules, "lagbench_first_try", raising=False)
    assert import_function("lagbench_first_try:f", "--predict")() == "working folder"


def test_a_module_name_imported_from_another_folder_is_read_from_the_working_folder_anew(tmp_path, monkeypatch):
    for sub, body in (("one", "def f():\n    return 1\n"), ("two", "def f():\n    return 2\n\ndef g():\n    return 3\n")):
        (tmp_path / sub).mkdir()
        (tmp_path / sub / "lagbench_same_name.py").write_text(body)
    monkeypatch.delitem(sys.modules, "lagbench_same_name", raising=False)
    monkeypatch.chdir(tmp_path / "one")
    assert import_function("lagbench_same_name:f", "--predict")() == 1
    kept = sys.modules["lagbench_same_name"]
    assert import_function("lagbench_same_name:f", "--predict")() == 1 and sys.modules["lagbench_same_name"] is kept
    monkeypatch.chdir(tmp_path / "two")   # the same name, another file: its own functions, not the first one's
    assert import_function("lagbench_same_name:f", "--predict")() == 2
    assert import_function("lagbench_same_name:g", "--predict")() == 3


def test_what_comes_back_is_checked_and_non_finite_rows_counted():
    with pytest.raises(UserCodeError, match="f\\(q, qdot\\) returned dict, not an array of numbers"):
        array_of("--predict", "m:f", "f(q, qdot)", {"a": 1})
    with pytest.raises(UserCodeError, match="returned shape \\(3,\\), expected \\(3, 1\\)"):
        array_of("--predict", "m:f", "f(q, qdot)", np.zeros(3), (3, 1))
    out = np.zeros((7, 2))
    out[2, 1], out[5, 0] = np.nan, np.inf
    assert nonfinite_rows(out) == 2 and nonfinite_failure(0, 7) is None
    assert nonfinite_failure(2, 7)["message"] == "non-finite on 2 of 7 held-out states"
