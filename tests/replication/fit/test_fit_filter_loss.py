"""`lagbench fit --loss-target filtered` (`replication.fit.filter_rows`, `Protocol.filter_loss`): on a simulated
pendulum recording with position noise, a fit trained on the filtered acceleration loss learns (its held-out
one-step error well below the null predictor's), its record names the filter it follows (the training file's
window, as its derivatives record it), and input it does not apply to fails in one line before any training."""
import numpy as np
import pytest
from fit_files_kit import edited, states

from lagbench.cli import main
from lagbench.files import results as R
from lagbench.files import user_data
from lagbench.replication.fit.simulate import simulate
from lagbench.replication.fit.task import fit
from lagbench.reports.sections_fit import _loss

NOISE = 0.003   # rad on every recorded angle (0.17 degrees), at 100 frames/s


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("filter_loss") / "pendulum.csv"
    simulate("pendulum", trajectories=6, duration=3.0, rate=100.0, noise=NOISE, seed=0).to_csv(path, index=False)
    return path


def test_a_fit_on_the_filtered_loss_learns_and_says_so(recording, tmp_path):
    """Through the command line: 300 steps of a small baseline. The training rows are those whose frames the
    window spans are all training rows (each training trajectory less window - 3 rows), and the held-out rows
    are scored as in every fit, by the one-step q-double-dot error."""
    out = tmp_path / "out"
    assert main(["fit", "--data", str(recording), "--model", "baseline", "--framework", "torch", "--steps", "300",
                 "--hidden", "32,32", "--patience", "0", "--loss-target", "filtered", "--out", str(out)]) == 0
    r = R.load_result(out / "units" / "fit" / "torch" / "baseline" / "seed0")
    window = r["eval_config"]["derivatives"]["window"]
    assert r["protocol"]["filter_loss"] == {"window": window, "polyorder": 3}
    train = user_data.rows(r["protocol"]["data"]["recipe"], "train")
    _, sizes = np.unique(train["traj"], return_counts=True)
    assert r["protocol"]["data"]["n_train"] == int(np.sum(sizes - (window - 3)))
    m = r["metrics"]
    assert m["heldout_l1"] < 0.4 * m["null_heldout_l1"], (m["heldout_l1"], m["null_heldout_l1"])
    assert _loss(r["protocol"]) == f"l1 on q-double-dot through the derivative filter (window {window}, order 3)"


@pytest.mark.parametrize("case, model, match", [
    ("a file of states", "baseline", "^--loss-target filtered: .*states.npz is a file of state samples"),
    ("given velocities", "baseline", "^--loss-target filtered: .*qdot.csv gives qdot, so its q-double-dot is not"),
    ("torques: the inverse dynamics", "baseline", "^--loss-target filtered: .*tau.csv has tau columns"),
    ("an HNN", "hnn", "^--loss-target filtered: an HNN's loss reads its time derivatives"),
])
def test_input_it_does_not_apply_to_fails_in_one_line(recording, tmp_path, case, model, match):
    data = {"a file of states": lambda: states(tmp_path / "states.npz"),
            "given velocities": lambda: edited(recording, tmp_path / "qdot.csv", qdot0=0.0),
            "torques: the inverse dynamics": lambda: edited(recording, tmp_path / "tau.csv", tau0=0.0),
            }.get(case, lambda: recording)()
    with pytest.raises(ValueError, match=match) as e:
        fit(data, out=tmp_path / "out", model=model, framework="torch", steps=2, hidden=(4,), loss_target="filtered")
    assert "\n" not in str(e.value)
    assert not (tmp_path / "out" / "units").exists()   # refused before anything trained


@pytest.mark.parametrize("model, edit, chosen", [("delan", {}, "filtered"), ("baseline", {}, "acceleration"),
                                                 ("lnn", {}, "acceleration"), ("delan", {"qdot0": 0.0}, "acceleration")])
def test_auto_chooses_the_filtered_loss_for_delan_on_estimated_derivatives_alone(recording, tmp_path, model, edit,
                                                                                chosen):
    """`--loss-target auto` (the default): the filtered loss for DeLaN on a trajectory file whose q-double-dot is
    estimated from q, the registered study's adoption; the acceleration loss for the LNN and the baseline (the
    study's arms that lost) and for a file that gives qdot. Recorded in the protocol and, where it chose the
    filtered loss, in eval_config with the reason; passed to `on_choices` always."""
    data = edited(recording, tmp_path / "given.csv", **edit) if edit else recording
    seen = {}
    r = fit(data, out=tmp_path / "out", model=model, framework="jax", steps=3, hidden=(4,), restarts=0,
            on_choices=seen.update)
    assert seen["loss_target"]["mode"] == "auto" and seen["loss_target"]["chosen"] == chosen
    assert ("filter_loss" in r["protocol"]) == (chosen == "filtered")
    assert ("loss_target" in r["eval_config"]) == (chosen == "filtered")
    given = fit(recording, out=tmp_path / "given", model="delan", framework="jax", steps=3, hidden=(4,),
                loss_target="acceleration") if model == "delan" and not edit else None
    if given is not None:   # as given: the acceleration loss, and nothing recorded of a choice
        assert "filter_loss" not in given["protocol"] and "loss_target" not in given["eval_config"]
