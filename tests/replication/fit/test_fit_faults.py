"""`lagbench fit` under changed data, repeated runs and bad options: nothing stale, nothing lost, no
silent failure (issue 25, cases 1, 2 and 6)."""
import numpy as np
import pandas as pd
import pytest

from lagbench.cli import build_parser, main
from lagbench.files import results as R
from lagbench.replication.fit.task import fit

FAST = {"model": "baseline", "steps": 4, "hidden": (8,), "batch": 16}


def _pendulum(path, scale=1.0, rows=40):
    rng = np.random.default_rng(3)
    q, qdot = rng.normal(size=(rows, 1)), rng.normal(size=(rows, 1))
    np.savez(path, q=q, qdot=qdot, qddot=-9.81 * np.sin(q) * scale)
    return path


def test_changed_data_is_trained_afresh_and_the_old_fit_is_kept(tmp_path):
    data, out = _pendulum(tmp_path / "d.npz"), tmp_path / "out"
    first = fit(data, out=out, **FAST)
    again = fit(data, out=out, **FAST)  # same bytes, same options: the verified earlier fit
    assert again["reused"] and again["checksum"] == first["checksum"]
    _pendulum(data, scale=100.0)
    second = fit(data, out=out, **FAST)
    assert "reused" not in second
    assert second["protocol"]["data"] != first["protocol"]["data"]
    assert second["final_train_loss"] != pytest.approx(first["final_train_loss"])
    assert len(list((out / "trained" / "jax").iterdir())) == 2  # one training per content
    (old,) = out.glob("units/fit/jax/baseline/superseded-*-seed0/result.json")
    assert R.load_result(old.parent)["checksum"] == first["checksum"]


def test_a_file_edited_after_setup_is_refused(tmp_path):
    from lagbench.files import user_data
    data = _pendulum(tmp_path / "d.npz")
    digest, _ = user_data.read(str(data))
    _pendulum(data, scale=2.0)
    with pytest.raises(ValueError, match="changed since"):
        user_data.split_rows(user_data.reference(str(data), digest).removeprefix("file:"), "acceleration", "train")


def _csv(path, header, rows=40, big=False):
    rng = np.random.default_rng(0)
    values = rng.normal(size=(rows, len(header)))
    if big:
        values[5, -1] = 1e300
    pd.DataFrame(values, columns=header).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("header, big, message", [
    (["q0", " qdot0", " qddot0"], False, None),  # spaces after the commas are ignored
    (["q0", "q2", "qdot0", "qdot1", "qddot0", "qddot1"], False, "without gaps"),
    (["q0", "qdot0", "qddot0"], True, "beyond the float32 range"),
    (["q0", "qdot0", "qddot0", "qdot0"], False, "column qdot0 named more than once"),   # not silently the first
    (["q0", " qdot0", "qddot0", "qdot0 "], False, "column qdot0 named more than once"),
])
def test_csv_headers_gaps_and_float32_range(tmp_path, header, big, message):
    path = _csv(tmp_path / "d.csv", header, big=big)
    if message is None:
        assert fit(path, out=tmp_path / "out", **FAST)["status"] == "ok"
    else:
        with pytest.raises(ValueError, match=message):
            fit(path, out=tmp_path / "out", **FAST)


@pytest.mark.parametrize("args, words", [
    (["--hidden", "8,abc"], ["--hidden", "128,128"]),
    (["--hidden", "0"], ["--hidden"]),
    (["--model", "gpt"], ["--model", "lnn, hnn, delan, baseline"]),
    (["--frameworks", "mxnet"], ["--frameworks", "jax, torch"]),
    (["--frameworks", "jax,torch"], ["--frameworks", "one framework"]),
    (["--loss", "huber"], ["--loss", "l1, mse"]),
    (["--steps", "0"], ["--steps", ">= 1"]),
    (["--batch", "-3"], ["--batch", ">= 1"]),
    (["--lr", "nan"], ["--lr", "> 0"]),
    (["--seed", "-1"], ["--seed", ">= 0"]),
    (["--horizon", "0"], ["--horizon", "> 0"]),
    (["--horizon", "nan"], ["--horizon", "> 0"]),
])
def test_bad_fit_options_name_the_option_before_any_work(tmp_path, capsys, args, words):
    out = tmp_path / "out"
    assert main(["fit", "--data", str(tmp_path / "absent.npz"), "--model", "baseline", "--out", str(out),
                 *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and all(w in err for w in words), err
    assert not out.exists()


def test_out_is_checked_before_training(tmp_path, capsys):
    data = _pendulum(tmp_path / "d.npz")
    (tmp_path / "file").write_text("x")
    assert main(["fit", "--data", str(data), "--model", "baseline", "--out", str(tmp_path / "file")]) == 2
    assert "--out" in capsys.readouterr().err
    assert not list(tmp_path.glob("**/trained"))


def test_a_failed_fit_exits_non_zero_with_its_reason(tmp_path, capsys):
    data = _pendulum(tmp_path / "d.npz")
    code = main(["fit", "--data", str(data), "--model", "baseline", "--out", str(tmp_path / "o"), "--steps", "3",
                 "--hidden", "8", "--lr", "1e38"])
    err = capsys.readouterr().err
    assert code == 1 and "fit failed: non-finite" in err, err


def test_a_moved_folder_or_a_renamed_copy_of_the_data_reuses_the_fit(tmp_path):
    """A fit is keyed by the data's content and the options, never by a path (issue 58, item 5)."""
    import shutil

    data, out = _pendulum(tmp_path / "d.npz"), tmp_path / "out"
    first = fit(data, out=out, **FAST)
    moved = tmp_path / "moved"
    shutil.move(out, moved)
    again = fit(data, out=moved, **FAST)
    assert again.get("reused") and again["checksum"] == first["checksum"]
    assert not list(moved.glob("units/fit/*/*/superseded-*"))
    copy = tmp_path / "renamed.npz"
    shutil.copy(data, copy)
    third = fit(copy, out=moved, **FAST)
    assert third.get("reused") and third["final_train_loss"] == first["final_train_loss"]
    # other bytes are another fit
    _pendulum(copy, scale=2.0)
    assert "reused" not in fit(copy, out=moved, **FAST)


def test_evaluate_takes_fitted_and_reads_the_old_model_spelling_with_a_notice(tmp_path, capsys):
    """`evaluate --fitted DIR`; `--model DIR` (its old spelling; in `fit`, --model is the model kind) still
    works and says so; neither, or both, is one line naming --fitted."""
    from lagbench.replication.fit import cli

    parser = build_parser()
    args = parser.parse_args(["evaluate", "--model", "results/fit", "--data", "d.csv"])
    assert cli._fitted_folder(args) == "results/fit"
    assert "note: --model is now --fitted;" in capsys.readouterr().err
    args = parser.parse_args(["evaluate", "--fitted", "results/fit", "--data", "d.csv"])
    assert cli._fitted_folder(args) == "results/fit" and capsys.readouterr().err == ""
    for argv in (["--data", "d.csv"], ["--fitted", "a", "--model", "b", "--data", "d.csv"]):
        assert main(["evaluate", *argv, "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err
        assert err.startswith("lagbench: error: --") and "--fitted" in err
    assert not (tmp_path / "o").exists()
