"""The filtered acceleration loss (`Protocol.filter_loss`): the model's q-double-dot at the frames about a row,
smoothed by the derivative filter's kernel (`replication.training.objective.filtered`, rows from
`replication.fit.filter_rows`). The kernel reproduces the Savitzky-Golay estimate exactly from second
differences, an exact model seen through it meets the filter's estimate where the row's own q-double-dot
misses it by the filter's bias, the two frameworks give one loss and one gradient on one set of weights, rows
never reach past an end or a missing frame, and the part keeps every other protocol's key."""
import json

import numpy as np
import pytest
from loss_kit import Exact, jax_loss, torch_loss

from lagbench import systems
from lagbench.models import ModelSpec, init_params
from lagbench.replication.fit.filter_rows import filter_rows, neighbours
from lagbench.replication.fit.simulate import simulate
from lagbench.replication.fit.trajectories import derivative
from lagbench.replication.training.objective import filtered
from lagbench.replication.training.protocol import Data, FilterLoss, Protocol, TrajectoryLoss
from lagbench.replication.training.protocol_parts import filter_kernel

FILE = Data("file:recording.csv#sha256=" + "0" * 64, n_train=4)   # a recipe by name: nothing here reads it
PART = FilterLoss(window=7, polyorder=3)


@pytest.mark.parametrize("window, polyorder", [(5, 3), (11, 3), (9, 2), (13, 5), (31, 3)])
def test_the_kernel_gives_the_filter_from_second_differences(window, polyorder):
    """For any positions x: the filter's second derivative at a sample (`trajectories.derivative`, the fit's own,
    times h^2) equals the kernel applied to the central second differences of the window - 2 samples about it,
    to rounding; the kernel has window - 2 taps, is symmetric and sums to 1 (it passes a constant q-double-dot)."""
    k = np.array(filter_kernel(window, polyorder))
    assert k.size == window - 2 and k.sum() == pytest.approx(1.0, abs=1e-12) and k == pytest.approx(k[::-1], abs=1e-12)
    x, h, half = np.random.default_rng(window).normal(size=(80, 2)), 0.01, (window - 2) // 2
    estimate = derivative(x, h, 2, window, polyorder) * h * h
    second = x[2:] - 2 * x[1:-1] + x[:-2]   # at samples 1 .. 78
    for i in range(window // 2, 80 - window // 2):   # every sample with a centred window
        assert np.einsum("j,jd->d", k, second[i - 1 - half:i + half]) == pytest.approx(estimate[i], abs=1e-9)


def test_an_exact_model_seen_through_the_filter_meets_its_estimate():
    """A noise-free pendulum recording at 25 frames/s, derivatives by a window of 15 (a large bias): the exact
    q-double-dot at a row misses the filter's estimate by the filter's bias; the exact q-double-dot at the frames
    about it, smoothed by the kernel, meets it up to the second difference's h^2 q''''/12, over 20 x closer."""
    df = simulate("pendulum", trajectories=3, duration=4.0, rate=25.0, seed=2, velocities=True)
    window, h, part = 15, 1 / 25, FilterLoss(window=15, polyorder=3)
    rows = []
    for _, g in df.groupby("traj"):
        q = g[["q0"]].to_numpy()
        est = derivative(q, h, 2, window, 3)
        keep = slice(window // 2, len(q) - window // 2)   # the fit drops the filter's ends
        rows.append({"traj": g["traj"].to_numpy()[keep], "t": g["t"].to_numpy()[keep], "q": q[keep],
                     "qdot": g[["qdot0"]].to_numpy()[keep], "qddot": est[keep]})
    r = {k: np.concatenate([x[k] for x in rows]) for k in rows[0]}
    b = filter_rows(r, part)
    model = Exact(systems.get("pendulum"))
    through = filtered(model, b, part.kernel, np.concatenate)
    own = model.acceleration(b["q"], b["qdot"])
    miss_own, miss_through = np.abs(own - b["target"]).max(), np.abs(through - b["target"]).max()
    assert miss_through < miss_own / 20, (miss_through, miss_own)


def _batch(dof: int, taps: int, rng) -> dict:
    """Four rows of made-up numbers: their frames' states, frame after frame, and targets."""
    qt, vt = rng.normal(size=(4, taps * dof)), rng.normal(size=(4, taps * dof))
    mid = slice(taps // 2 * dof, (taps // 2 + 1) * dof)
    return {"q": qt[:, mid], "qdot": vt[:, mid], "q_taps": qt, "qdot_taps": vt, "target": rng.normal(size=(4, dof))}


@pytest.mark.parametrize("kind, fields, loss", [("lnn", {"dissipation": True, "periodic": (0,)}, "l1"),
                                                ("lnn", {"dissipation": True, "even_velocity": True}, "mse"),
                                                ("baseline", {}, "mse"), ("delan", {"dissipation": True}, "l1")])
def test_the_frameworks_give_one_loss_and_one_gradient(kind, fields, loss):
    """float64, one set of weights loaded into both: the loss to 1e-12 and every parameter's gradient to 1e-10
    of its largest entry (of 1e-3 of the largest of all, for one that is 0)."""
    spec = ModelSpec(kind=kind, dof=2, hidden=(8, 8), dtype="float64", init="xavier", **fields)
    params = init_params(spec, seed=0)
    batch = _batch(2, len(PART.kernel), np.random.default_rng(0))
    protocol = Protocol(data=FILE, steps=1, batch=4, dtype="float64", loss=loss, l2=1e-3, filter_loss=PART)
    (lj, gj), (lt, gt) = jax_loss(spec, params, protocol, batch), torch_loss(spec, params, protocol, batch)
    assert lj == pytest.approx(lt, rel=1e-12)
    assert gj.keys() == gt.keys()
    largest = max(np.max(np.abs(g)) for g in gj.values())
    assert largest > 0
    for name in gj:
        assert np.max(np.abs(gj[name] - gt[name])) <= 1e-10 * max(np.max(np.abs(gj[name])), 1e-3 * largest), name
    # the frames' smoothed q-double-dot, not the row's own: without the part the same weights score otherwise
    assert abs(torch_loss(spec, params, protocol.replace(filter_loss=None), batch)[0] - lt) > 1e-6 * abs(lt)


def test_rows_never_reach_past_an_end_or_a_missing_frame():
    """Two trajectories of 10 and 6 frames, the first without its frame 5 (a filled frame, dropped): 5 taps need
    the two frames either side, so the first keeps frame 2 alone (frames 6-9 are four in a row) and the second
    its frames 2 and 3; each row's frames in time order, coordinates within a frame."""
    t = np.arange(10) * 0.01
    keep = np.arange(10) != 5
    q = np.r_[np.sin(t[keep]), np.cos(t[:6])][:, None] * [1.0, 2.0]
    r = {"traj": np.r_[np.zeros(9), np.ones(6)], "t": np.r_[t[keep], t[:6]], "q": q, "qdot": -q,
         "qddot": np.arange(30.0).reshape(15, 2)}
    rows, at = neighbours(r, 5)
    assert rows.tolist() == [2, 11, 12] and at.tolist() == [[0, 1, 2, 3, 4], [9, 10, 11, 12, 13],
                                                            [10, 11, 12, 13, 14]]
    b = filter_rows(r, FilterLoss(window=7, polyorder=3))
    assert b["target"] == pytest.approx(r["qddot"][rows]) and b["q"] == pytest.approx(q[rows])
    frames = [9, 10, 11, 12, 13]
    assert b["q_taps"][1] == pytest.approx(q[frames].ravel()) and b["qdot_taps"][1] == pytest.approx(-q[frames].ravel())


def test_the_part_is_stored_only_when_on_and_checked():
    p = Protocol(data=FILE, steps=10, batch=4, filter_loss=FilterLoss(window=11, polyorder=3))
    plain = p.replace(filter_loss=None)
    assert "filter_loss" not in plain.to_dict() and p.to_dict()["filter_loss"] == {"window": 11, "polyorder": 3}
    assert Protocol.from_dict(json.loads(json.dumps(p.to_dict()))) == p and p.key() != plain.key()
    assert p.objective_key() != plain.objective_key()   # a compiled step is never shared with the one-step loss
    for bad, match in (({"task": "hamiltonian"}, "task acceleration, got hamiltonian"),
                       ({"data": Data("pendulum_iid", n_train=4)}, "a file recipe, got 'pendulum_iid'"),
                       ({"trajectory_loss": TrajectoryLoss(frames=2, substeps=1)}, "use one of them")):
        with pytest.raises(ValueError, match=match):
            p.replace(**bad)
    for fields, match in (({"window": 10}, "filter loss window must be odd, got 10"),
                          ({"window": 3}, "filter loss window must be an integer >= 5"),
                          ({"polyorder": 1}, "filter loss polyorder must be an integer >= 2")):
        with pytest.raises(ValueError, match=match):
            FilterLoss(**{"window": 11, "polyorder": 3, **fields})
