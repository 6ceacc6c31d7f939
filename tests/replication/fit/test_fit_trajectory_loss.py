"""`lagbench fit --loss-target trajectory` (`replication.fit.windows`, `Protocol.trajectory_loss`): on a simulated
pendulum recording with position noise, a fit trained on windows of the recording learns (its held-out
one-step error well below the null predictor's), its record says which loss trained it, and bad input fails
in one line before any training."""
import numpy as np
import pytest
from fit_files_kit import edited, states

from lagbench.cli import main
from lagbench.files import results as R
from lagbench.files import user_data
from lagbench.replication.fit.simulate import simulate
from lagbench.replication.fit.task import fit

NOISE = 0.003   # rad on every recorded angle (0.17 degrees), at 100 frames/s


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("trajectory_loss") / "pendulum.csv"
    simulate("pendulum", trajectories=6, duration=3.0, rate=100.0, noise=NOISE, seed=0).to_csv(path, index=False)
    return path


def test_a_fit_on_windows_of_a_noisy_recording_learns(recording, tmp_path):
    """Through the command line: 8-frame windows, one RK4 step a frame, 300 steps of a small baseline. The
    training rows are every recorded frame with 8 after it on its training trajectory (the held-out
    trajectories and the derivative filter's ends left out), and the held-out rows are scored as in every
    fit, by the one-step q-double-dot error."""
    out = tmp_path / "out"
    assert main(["fit", "--data", str(recording), "--model", "baseline", "--framework", "torch", "--steps", "300",
                 "--hidden", "32,32", "--patience", "0", "--loss-target", "trajectory", "--horizon-frames", "8",
                 "--horizon-substeps", "1", "--out", str(out)]) == 0
    r = R.load_result(out / "units" / "fit" / "torch" / "baseline" / "seed0")
    assert r["protocol"]["trajectory_loss"] == {"frames": 8, "substeps": 1, "scale": "acceleration"}
    train = user_data.rows(r["protocol"]["data"]["recipe"], "train")
    _, sizes = np.unique(train["traj"], return_counts=True)
    assert r["protocol"]["data"]["n_train"] == int(np.sum(sizes - 8))
    m = r["metrics"]
    assert m["heldout_l1"] < 0.4 * m["null_heldout_l1"], (m["heldout_l1"], m["null_heldout_l1"])


@pytest.mark.parametrize("case, options, match", [
    ("frames below 1", {"horizon_frames": 0}, "^--horizon-frames: 0 is not valid; expected an integer >= 1$"),
    ("frames beyond every trajectory", {"horizon_frames": 1000},
     r"^--horizon-frames 1000: no training trajectory holds 1001 frames in a row \(the longest run has \d+"),
    ("a file of states", {}, "^--loss-target trajectory: .*states.npz is a file of state samples"),
    ("torques: the inverse dynamics", {}, "^--loss-target trajectory: .*tau.csv has tau columns"),
    ("substeps without the trajectory loss", {"loss_target": "acceleration", "horizon_substeps": 4},
     "^--horizon-substeps: an option of the trajectory loss; give it with --loss-target trajectory$"),
])
def test_bad_input_fails_in_one_line(recording, tmp_path, case, options, match):
    data = {"a file of states": lambda: states(tmp_path / "states.npz"),
            "torques: the inverse dynamics": lambda: edited(recording, tmp_path / "tau.csv", tau0=0.0)}.get(case, lambda: recording)()
    with pytest.raises(ValueError, match=match) as e:
        fit(data, out=tmp_path / "out", model="baseline", framework="torch", steps=2, hidden=(4,),
            **{"loss_target": "trajectory", **options})
    assert "\n" not in str(e.value)
    assert not (tmp_path / "out" / "units").exists()   # refused before anything trained


def test_a_run_shorter_than_a_window_holds_no_window():
    import numpy as np

    from lagbench.replication.fit.windows import consecutive

    for size in range(7):
        assert consecutive(np.arange(size), 5).tolist() == ([0] if size == 6 else [])
    assert consecutive(np.array([0, 1, 2, 4, 5, 6, 7, 8]), 3).tolist() == [3, 4]
