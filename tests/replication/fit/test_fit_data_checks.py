"""`lagbench fit`'s data checks explain what is wrong with a file (issue 85, item 4): times in milliseconds
named as such against --system's time scale, the separator sniffed, the first bad row named by its line and
trajectory, a one-row trajectory's error without library warnings on the way."""
import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.files import user_data
from lagbench.replication.fit import rows as fit_data
from lagbench.replication.fit import time_base, trajectories
from lagbench.replication.fit.resolve import resolved

RATE = 50.0


def _recording(path, unit="s", n_traj=3, n=60, sep=","):
    """Pendulum-like trajectories sampled at 50 Hz, t in seconds or integer milliseconds."""
    frames = []
    for k in range(n_traj):
        t = np.arange(n) / RATE
        frames.append(pd.DataFrame({"traj": k, "t": np.rint(t * 1000).astype(int) if unit == "ms" else t,
                                    "q0": 0.5 * np.cos(1.2 * t + k)}))
    pd.concat(frames).to_csv(path, index=False, sep=sep)
    return path


def _fit(tmp_path, data, *args):
    return main(["fit", "--data", str(data), "--model", "baseline", "--steps", "3", "--hidden", "8", "--out",
                 str(tmp_path / "out"), *args])


def test_times_in_milliseconds_are_named_against_the_systems_time_scale(tmp_path, capsys):
    ms = _recording(tmp_path / "ms.csv", unit="ms")
    assert _fit(tmp_path, ms, "--system", "pendulum") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "look like milliseconds" in err and "--time-unit ms" in err, err
    assert "pendulum's time scale" in err and not (tmp_path / "out").exists()
    resolved(str(ms), {"model": "baseline", "system": "pendulum", "time_unit": "ms"})   # stated: accepted
    resolved(str(ms), {"model": "baseline"})   # without --system there is no time scale to check against
    # read in milliseconds, the rows are those of the same recording in seconds
    s = _recording(tmp_path / "s.csv")
    resolved(str(s), {"model": "baseline", "system": "pendulum"})
    in_ms = pd.read_csv(fit_data.prepare(tmp_path / "p", ms, time_unit="ms").reference.removeprefix("file:")
                        .split("#")[0])
    in_s = pd.read_csv(fit_data.prepare(tmp_path / "p", s).reference.removeprefix("file:").split("#")[0])
    np.testing.assert_allclose(in_ms["t"], in_s["t"], atol=1e-12)
    np.testing.assert_allclose(in_ms["qddot0"], in_s["qddot0"], rtol=1e-9, atol=1e-9)


def test_seconds_given_as_milliseconds_too_coarse_and_a_state_file_are_named(tmp_path):
    coarse = tmp_path / "coarse.csv"
    pd.DataFrame({"t": np.arange(40) * 5000.0, "q0": np.zeros(40)}).to_csv(coarse, index=False)
    with pytest.raises(ValueError, match="too far apart for its motion in seconds or milliseconds"):
        time_base.check_unit(coarse, user_data.read(str(coarse))[1], "pendulum", "s")
    state = tmp_path / "state.npz"
    np.savez(state, q=np.zeros((30, 1)), qdot=np.zeros((30, 1)), qddot=np.zeros((30, 1)))
    with pytest.raises(ValueError, match="^--time-unit ms: .* has no t column"):
        resolved(str(state), {"model": "baseline", "time_unit": "ms"})


@pytest.mark.parametrize("system", ["stiff_chain", "pendulum", "relativistic"])
def test_a_50_hz_recording_passes_in_seconds_and_is_refused_in_milliseconds(system):
    scale = time_base.time_scale(system)   # the suite's fastest, a middling and its slowest system
    assert 1 / RATE < scale < 1000 / RATE


@pytest.mark.parametrize("sep, decimal", [(";", "."), ("\t", "."), (";", ",")])
def test_semicolon_and_tab_separated_files_are_read(tmp_path, sep, decimal):
    comma = user_data.read(str(_recording(tmp_path / "c.csv")))[1]
    other = tmp_path / "o.csv"
    pd.read_csv(tmp_path / "c.csv").to_csv(other, index=False, sep=sep, decimal=decimal)
    d = user_data.read(str(other))[1]
    assert set(d) == set(comma)
    for k in d:
        np.testing.assert_allclose(d[k], comma[k])


def test_a_nan_row_is_named_by_its_line_and_trajectory(tmp_path, capsys):
    path = _recording(tmp_path / "nan.csv")
    df = pd.read_csv(path)
    df.loc[[75, 90], "q0"] = np.nan   # rows 75 and 90: trajectory 1, lines 77 and 92 (the header is line 1)
    df.to_csv(path, index=False)
    assert _fit(tmp_path, path) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "2 rows with NaN or infinite values (in q)" in err, err
    assert "the first at line 77, trajectory 1, t = 0.3" in err, err
    npz = tmp_path / "nan.npz"
    q = np.zeros((30, 1))
    q[4] = np.inf
    np.savez(npz, q=q, qdot=q, qddot=np.zeros((30, 1)))
    with pytest.raises(ValueError, match=r"1 row with NaN or infinite values \(in q, qdot\), the first at row 4"):
        user_data.read(str(npz))


def test_a_one_row_trajectory_gives_its_error_without_warnings(tmp_path, capsys):
    path = _recording(tmp_path / "one.csv")
    pd.concat([pd.read_csv(path), pd.DataFrame({"traj": [9], "t": [0.0], "q0": [0.1]})]).to_csv(path, index=False)
    with pytest.raises(ValueError, match="trajectory 9 has 1 sample; estimating"):  # a NumPy warning fails here
        trajectories.with_derivatives(user_data.read(str(path))[1], str(path))
    assert _fit(tmp_path, path, "--quiet") == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and "Warning" not in captured.err + captured.out, captured.err
