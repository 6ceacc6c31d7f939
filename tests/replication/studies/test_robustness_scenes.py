"""The robustness study's scenes (`replication.studies.robustness_scenes`): the nominal data are the exact
inverse dynamics, friction adds exactly its torque and the plant obeys it, noise goes only into the
recording, and the tracker is control.py's on the nominal arm, bit for bit."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.replication.studies import control as C
from lagbench.replication.studies import robustness_scenes as S
from lagbench.replication.studies.robustness_scenes import Plant, Scene, scene_data
from lagbench.systems.arm_data import arm_dataset

ARM = systems.get("two_link_arm")


def test_the_nominal_scene_is_the_exact_inverse_dynamics_without_noise():
    d = scene_data(Scene("nominal"), "train", 3, 40, seed=5, noise_seed=9)
    ref = arm_dataset("train", 3, 40, seed=5, cache=False)
    for k in ("t", "q", "qdot", "qddot"):
        assert np.array_equal(d[k], ref[k])
    assert np.array_equal(d["tau"], ARM.inverse_dynamics(d["q"], d["qdot"], d["qddot"]))
    assert np.array_equal(d["tau_rec"], d["tau"]) and np.array_equal(d["q_rec"], d["q"])


@pytest.mark.parametrize("scene", [Scene("coulomb", 2.0), Scene("viscous", 0.5)])
def test_friction_adds_exactly_its_torque_and_the_plant_obeys_the_data(scene):
    d = scene_data(scene, "test", 2, 50, seed=1)
    free = scene_data(Scene("nominal"), "test", 2, 50, seed=1)
    friction = scene.coulomb * np.tanh(d["qdot"] / S.V_S) + scene.friction * d["qdot"]
    assert np.allclose(d["tau"] - free["tau"], friction, rtol=0, atol=1e-12)
    assert np.abs(friction).max() > 0.4 * scene.magnitude
    plant = Plant(scene)
    q, v, a, tau = (d[k].reshape(-1, 2) for k in ("q", "qdot", "qddot", "tau"))
    assert np.allclose(plant.acceleration(q, v, tau=tau), a, rtol=0, atol=1e-9)
    assert np.allclose(plant.inverse_dynamics(q, v, a), tau, rtol=0, atol=1e-12)


def test_noise_goes_into_the_recording_only_and_is_drawn_from_its_own_seed():
    t = scene_data(Scene("torque_noise", 2.0), "train", 4, 100, seed=0, noise_seed=1)
    assert np.array_equal(t["tau"], scene_data(Scene("nominal"), "train", 4, 100, seed=0)["tau"])
    assert np.array_equal(t["q_rec"], t["q"]) and abs(np.std(t["tau_rec"] - t["tau"]) - 2.0) < 0.15
    again = scene_data(Scene("torque_noise", 2.0), "train", 4, 100, seed=0, noise_seed=1)["tau_rec"]
    other = scene_data(Scene("torque_noise", 2.0), "train", 4, 100, seed=0, noise_seed=2)["tau_rec"]
    assert np.array_equal(again, t["tau_rec"]) and not np.array_equal(other, t["tau_rec"])
    s = scene_data(Scene("sensor_noise", 0.03), "train", 4, 100, seed=0, noise_seed=1)
    assert np.array_equal(s["tau_rec"], s["tau"]) and abs(np.std(s["q_rec"] - s["q"]) - 0.03) < 0.003


def test_the_recording_leaves_the_derivatives_to_the_filter_only_under_sensor_noise(tmp_path):
    for scene in (Scene("sensor_noise", 0.03), Scene("coulomb", 0.5)):
        d = scene_data(scene, "train", 2, 30, seed=0)
        S.write_recording(d, tmp_path / "r.npz", scene)
        with np.load(tmp_path / "r.npz") as z:
            assert ("qdot" in z.files) == ("qddot" in z.files) == (scene.kind != "sensor_noise")
            assert np.array_equal(z["q"], d["q_rec"].reshape(-1, 2)) and np.array_equal(z["traj"][28:32], [0, 0, 1, 1])
    before = (tmp_path / "r.npz").read_bytes()
    S.write_recording(d, tmp_path / "r.npz", scene)   # the same arrays: the file (and the fits keyed on it) stays
    assert (tmp_path / "r.npz").read_bytes() == before
    S.write_recording(scene_data(scene, "train", 2, 30, seed=1), tmp_path / "r.npz", scene)
    assert (tmp_path / "r.npz").read_bytes() != before


def test_bad_scenes_are_refused():
    with pytest.raises(ValueError, match="unknown scene kind"):
        Scene("backlash", 1.0)
    with pytest.raises(ValueError, match="magnitude"):
        Scene("viscous", 0.0)
    assert Scene("viscous", 2.0).id == "viscous-2" and Scene("viscous", 2.0).coulomb == 0.0


def test_the_tracker_is_control_py_s_on_the_nominal_arm_and_feels_the_scene_s_friction():
    refs = C.references("test", n=2, duration=0.3)
    mine = C.track(ARM.inverse_dynamics, refs, plant=Plant(Scene("nominal")))
    theirs = C.track(ARM.inverse_dynamics, refs)
    assert all(np.array_equal(mine[k], theirs[k]) for k in ("q", "tau", "diverged"))
    sticky = Plant(Scene("coulomb", 2.0))
    exact = C.scores(C.track(sticky.inverse_dynamics, refs, plant=sticky), refs)["track_mse"]
    unaware = C.scores(C.track(ARM.inverse_dynamics, refs, plant=sticky), refs)["track_mse"]
    assert exact < 1e-2 * unaware


def test_a_scene_s_plant_compiled_is_its_numpy_plant_to_rounding():
    sticky = Plant(Scene("coulomb", 2.0))
    rng = np.random.default_rng(1)
    q, v, tau = (rng.normal(size=(3, 2)) for _ in range(3))
    h = 1.0 / C.RATE / C.SUBSTEPS
    compiled = C.period(sticky, h, periods=C.COMPILE_FROM)(q, v, tau)
    for want, got in zip(C.hold(sticky, q, v, tau, h), compiled, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    smooth = C.period(Plant(Scene("viscous", 2.0)), h, periods=C.COMPILE_FROM)(q, v, tau)   # not the same program
    assert not np.allclose(smooth[1], compiled[1])
