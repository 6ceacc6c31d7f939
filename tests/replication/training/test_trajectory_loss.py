"""The trajectory loss (`Protocol.trajectory_loss`): the model's motion over windows of a recording, integrated by
RK4 (`replication.training.objective.positions`) on windows cut from its rows (`replication.fit.windows`).
The two frameworks give one loss and one gradient on one set of weights, an exact model reaches the recorded
positions to RK4's order, windows never cross an end or a missing frame, and the part keeps every other
protocol's key."""
import json

import numpy as np
import pytest
from loss_kit import Exact, jax_loss, torch_loss

from lagbench import systems
from lagbench.models import ModelSpec, init_params
from lagbench.replication.fit.simulate import simulate
from lagbench.replication.fit.windows import scale_of, windows
from lagbench.replication.training.objective import positions
from lagbench.replication.training.protocol import Data, Protocol, TrajectoryLoss

FILE = Data("file:recording.csv#sha256=" + "0" * 64, n_train=4)   # a recipe by name: nothing here reads it
PART = TrajectoryLoss(frames=2, substeps=1)


def _batch(dof: int, frames: int, rng) -> dict:
    """Four windows of made-up numbers: start states, frame steps near 0.02 s, the acceleration scale, targets."""
    h = 0.02 + 0.002 * rng.random((4, 1))
    return {"q": rng.normal(size=(4, dof)), "qdot": rng.normal(size=(4, dof)), "h": h,
            "scale": scale_of(h, frames, "l1", "acceleration"), "target": rng.normal(size=(4, frames * dof))}


@pytest.mark.parametrize("kind, fields, task, loss", [("lnn", {"dissipation": True, "periodic": (0,)}, "acceleration", "l1"),
                                                      ("baseline", {}, "acceleration", "mse"),
                                                      ("delan", {}, "acceleration", "l1"), ("hnn", {}, "hamiltonian", "l1")])
def test_the_frameworks_give_one_loss_and_one_gradient(kind, fields, task, loss):
    """float64, one set of weights loaded into both: the loss to 1e-12 and every parameter's gradient to 1e-10
    of its largest entry (of 1e-3 of the largest of all, for one that is 0). Each kind's vector field, dissipation
    and periodic inputs included."""
    spec = ModelSpec(kind=kind, dof=2, hidden=(8, 8), dtype="float64", init="xavier", **fields)
    params = init_params(spec, seed=0)
    batch = _batch(2, PART.frames, np.random.default_rng(0))
    protocol = Protocol(data=FILE, steps=1, batch=4, dtype="float64", task=task, loss=loss, l2=1e-3,
                        trajectory_loss=PART)
    (lj, gj), (lt, gt) = jax_loss(spec, params, protocol, batch), torch_loss(spec, params, protocol, batch)
    assert lj == pytest.approx(lt, rel=1e-12)
    assert gj.keys() == gt.keys()
    largest = max(np.max(np.abs(g)) for g in gj.values())
    assert largest > 0
    for name in gj:   # (a scalar output's last bias has no gradient: it moves no derivative of L or H)
        assert np.max(np.abs(gj[name] - gt[name])) <= 1e-10 * max(np.max(np.abs(gj[name])), 1e-3 * largest), name
    # the positions' loss, not the one-step loss: without the part the same weights score otherwise
    other = {**batch, "target": batch["target"][:, :2 if task == "acceleration" else 4]}   # the task's width
    assert abs(torch_loss(spec, params, protocol.replace(trajectory_loss=None), other)[0] - lt) > 1e-6 * abs(lt)


def test_an_exact_model_reaches_the_recorded_positions_to_rk4_order():
    """On a noise-free recording of the pendulum (diffrax at tight tolerances), the true dynamics integrated by
    `positions` miss the recorded positions by RK4's error: each doubling of the substeps divides it by about
    2^4 (the method's order), and it is small against the motion."""
    df = simulate("pendulum", trajectories=3, duration=2.0, rate=20.0, seed=1, velocities=True)
    r = {"traj": df["traj"].to_numpy(float), "t": df["t"].to_numpy(), "q": df[["q0"]].to_numpy(),
         "qdot": df[["qdot0"]].to_numpy()}
    model, errors = Exact(systems.get("pendulum")), []
    for substeps in (1, 2, 4):
        b = windows(r, TrajectoryLoss(frames=4, substeps=substeps), "l1")
        pred = positions(model, "acceleration", b, substeps, np.concatenate)
        errors.append(np.max(np.abs(pred - b["target"]) / b["scale"]))
        motion = np.max(np.abs(b["target"]) / b["scale"])
    assert errors[-1] < 1e-5 * motion
    for coarse, fine in zip(errors, errors[1:], strict=False):
        assert 10 < coarse / fine < 24, errors


def test_windows_never_cross_an_end_or_a_missing_frame():
    """Two trajectories of 10 and 6 frames, the first without its frame 5 (a filled frame, dropped): a window of
    K = 3 needs 4 frames in a row, so the first holds 2 + 1 (from frames 0-4 and 6-9) and the second 3."""
    t = np.arange(10) * 0.01
    keep = np.arange(10) != 5
    r = {"traj": np.r_[np.zeros(9), np.ones(6)], "t": np.r_[t[keep], t[:6]],
         "q": np.r_[np.sin(t[keep]), np.cos(t[:6])][:, None] * [1.0, 2.0], "qdot": np.zeros((15, 2))}
    b = windows(r, TrajectoryLoss(frames=3, substeps=1, scale="none"), "l1")
    assert b["q"][:, 0].tolist() == pytest.approx(np.r_[np.sin(t[[0, 1, 6]]), np.cos(t[:3])].tolist())
    assert b["h"] == pytest.approx(np.full((6, 1), 0.01)) and np.all(b["scale"] == 1.0)
    first = (np.sin(t[1:4]) - np.sin(t[0]))[:, None] * [1.0, 2.0]   # frame by frame, coordinates within a frame
    assert b["target"][0] == pytest.approx(first.ravel())
    # the acceleration scale: a constant q-double-dot error e moves frame k by e (k h)^2 / 2; the scaled L1 is |e|
    e, h, k = 0.7, 0.01, np.arange(1, 4)
    assert np.sum(e * (k * h) ** 2 / 2 * scale_of(np.array(h), 3, "l1", "acceleration")) == pytest.approx(e)
    assert np.sum((e * (k * h) ** 2 / 2 * scale_of(np.array(h), 3, "mse", "acceleration")) ** 2) == pytest.approx(e * e)


def test_the_part_is_stored_only_when_on_and_checked():
    p = Protocol(data=FILE, steps=10, batch=4, trajectory_loss=TrajectoryLoss(frames=5, substeps=2))
    plain = p.replace(trajectory_loss=None)
    assert "trajectory_loss" not in plain.to_dict() and p.to_dict()["trajectory_loss"] == {
        "frames": 5, "substeps": 2, "scale": "acceleration"}
    assert Protocol.from_dict(json.loads(json.dumps(p.to_dict()))) == p and p.key() != plain.key()
    assert p.objective_key() != plain.objective_key()   # a compiled step is never shared with the one-step loss
    for bad, match in (({"task": "inverse_dynamics"}, "task of acceleration or hamiltonian, got inverse_dynamics"),
                       ({"data": Data("pendulum_iid", n_train=4)}, "a file recipe, got 'pendulum_iid'")):
        with pytest.raises(ValueError, match=match):
            p.replace(**bad)
    for fields, match in (({"frames": 0}, "trajectory loss frames must be an integer >= 1"),
                          ({"substeps": 1.5}, "trajectory loss substeps must be an integer >= 1"),
                          ({"scale": "unit"}, "unknown trajectory loss scale 'unit'")):
        with pytest.raises(ValueError, match=match):
            TrajectoryLoss(**{"frames": 5, "substeps": 2, **fields})
