"""Held-out tracking during training (`Protocol.tracking`, `replication.training.tracking`): it reads the model
and changes no training number; its last point is the final model's held-out loss; the report draws it."""
import numpy as np
import pandas as pd
import pytest
from parity_rows import BY_NAME

from lagbench.replication.evaluation.adapters import adapter
from lagbench.replication.training import scouting
from lagbench.replication.training.objective import loss_value, predict
from lagbench.replication.training.protocol import Tracking
from lagbench.replication.training.tracking import TRACK_STATES, Tracker
from lagbench.replication.training.train import run_training

SPEC = BY_NAME["lnn_scouted"].spec   # a small float64 double-pendulum LNN
PLAIN = scouting.scout_protocol(BY_NAME["lnn_scouted"].protocol).replace(steps=9, log_every=2)


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_tracking_changes_no_training_number_and_ends_at_the_final_models_loss(framework):
    off = run_training(framework, SPEC, PLAIN, 1)
    on = run_training(framework, SPEC, PLAIN.replace(tracking=Tracking(every=4)), 1)
    for k in off.params:
        np.testing.assert_array_equal(on.params[k], off.params[k])
    assert [r["loss"] for r in on.log] == [r["loss"] for r in off.log]
    tracked = [r for r in on.log if "heldout_loss" in r]
    assert [r["step"] for r in tracked] == [0, 4, 8]
    assert [r["samples"] for r in tracked] == [PLAIN.batch, 5 * PLAIN.batch, 9 * PLAIN.batch]
    assert tracked[0]["train_s"] <= tracked[1]["train_s"] <= tracked[2]["train_s"]
    t = Tracker(framework, SPEC, PLAIN.replace(tracking=Tracking(every=4)))
    pred = predict(adapter(framework, SPEC, on.params), SPEC.kind, PLAIN.task, t.batch, np.concatenate)
    final = loss_value(pred, t.batch["target"], t.batch.get("weight"), PLAIN.loss)
    assert len(t.batch["target"]) == min(TRACK_STATES, PLAIN.data.n_heldout)
    np.testing.assert_allclose(tracked[-1]["heldout_loss"], final, rtol=1e-10)


def test_a_scouted_run_tracks_its_continuation_with_the_scouts_samples_counted():
    p = BY_NAME["lnn_scouted"].protocol.replace(steps=6, log_every=3, tracking=Tracking(every=3))
    out = run_training("jax", SPEC, p, 0)
    tracked = [r for r in out.log if "heldout_loss" in r]
    scouts = p.scouting.count * scouting.scout_steps(p) * scouting.scout_protocol(p).batch
    assert tracked[0]["samples"] == scouts + p.batch and tracked[-1]["samples"] == scouting.budget_samples(p)
    assert tracked[0]["train_s"] > 0   # the scouts' time counts


def test_kept_checkpoints_are_stored_only_when_asked_so_other_protocols_keep_their_keys():
    from lagbench.replication.training.protocol import Protocol

    assert PLAIN.replace(tracking=Tracking(every=4)).to_dict()["tracking"] == {"every": 4}
    kept = PLAIN.replace(tracking=Tracking(every=4, keep=True))
    assert kept.to_dict()["tracking"] == {"every": 4, "keep": True}
    assert Protocol.from_dict(kept.to_dict()) == kept
    assert Protocol.from_dict(PLAIN.replace(tracking=Tracking(every=4)).to_dict()).tracking.keep is False
    with pytest.raises(ValueError, match="keep"):
        Tracking(every=4, keep="yes")


def test_tracking_must_fall_on_logged_steps():
    with pytest.raises(ValueError, match="not a multiple of log_every"):
        PLAIN.replace(tracking=Tracking(every=3))


class _Unit:
    def __init__(self, model, fw, log):
        self.model, self.framework, self._log = model, fw, log

    def table(self, name):
        return self._log


def test_work_precision_draws_tracked_logs_only(tmp_path):
    from lagbench.reports.figures_precision import tracked, work_precision

    log = pd.DataFrame({"step": [0, 1, 2], "loss": [3.0, 2.0, 1.0], "heldout_loss": [3.0, np.nan, 1.5],
                        "samples": [8, np.nan, 24], "train_s": [0.1, np.nan, 0.3]})
    units = [_Unit("lnn", "jax", log), _Unit("lnn", "jax", log.assign(heldout_loss=[4.0, np.nan, 2.5]))]
    d = tracked(units)[("lnn", "jax")]
    assert list(d["samples"]) == [8, 24] and list(d["lo"]) == [3.0, 1.5] and list(d["hi"]) == [4.0, 2.5]
    assert work_precision(units, tmp_path / "wp.png") and (tmp_path / "wp.png").stat().st_size > 0
    untracked = [_Unit("lnn", "jax", log[["step", "loss"]])]
    assert not work_precision(untracked, tmp_path / "none.png") and not (tmp_path / "none.png").exists()
