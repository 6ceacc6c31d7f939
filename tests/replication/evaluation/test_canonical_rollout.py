"""An HNN on canonical (q, p) rolled out by its own H (`replication.evaluation.canonical`): with an exact H as
the 'learned' one it retraces the truth on the relativistic particle, where M^-1 p is not the velocity (the
particle has no mass matrix; its rest mass gives gamma qdot, past c at high speed), and on a quadratic
kinetic energy, where dH/dp and M(q)^-1 p agree. Through both routines that roll it out: the energy
rollout (`routines._model_rollout`, claim 10's pendulum) and the short rollouts (claim 3's `hnn_qp`), which
read the true system's velocity at each predicted state (q, p) (`state_velocity`), so that an energy is
H_true(q, p) whatever the learned dH/dp."""
import numpy as np
import pytest

import lagbench.systems.trajectories
from lagbench import systems
from lagbench.replication.claims import CLAIMS
from lagbench.replication.evaluation.canonical import canonical_rollout, state_velocity, velocity
from lagbench.replication.evaluation.registry import EVALUATIONS
from lagbench.replication.evaluation.routines import Context, system_of
from lagbench.replication.run.runner import plan
from lagbench.systems.derive import NotQuadraticError

V0 = np.array([[0.9], [0.99], [-0.999]])   # |qdot| near c: gamma 2.3, 7.1, 22
G = np.array([5.0, -3.0, 2.0])
Q0 = np.array([[0.0], [1.0], [-2.0]])


def standard_h(q, p, extra):
    """H = sqrt(p^2 + 1) - g q (m = c = 1; g the extra input): (dH/dp, -dH/dq)."""
    return p / np.sqrt(1.0 + p ** 2), np.broadcast_to(extra[:, :1], p.shape).copy()


def standard_closed_form(t):
    """q, qdot (B, T, 1) of the standard relativistic particle in a uniform field: p = p0 + g t."""
    p0 = V0 / np.sqrt(1.0 - V0 ** 2)
    p = p0 + G[:, None] * t[None, :]
    energy = np.sqrt(1.0 + p ** 2)
    q = Q0 + (energy - np.sqrt(1.0 + p0 ** 2)) / G[:, None]
    return q[..., None], (p / energy)[..., None]


def test_the_relativistic_particle_is_rolled_out_by_its_own_h_where_m_inverse_p_fails():
    s = systems.get("relativistic_standard")
    t = np.linspace(0.0, 1.0, 51)
    q, p = canonical_rollout(standard_h, s, Q0, V0, t, 0.01, extra=G[:, None], momentum_kw={"g": G})
    qdot = velocity(standard_h, q, p, G[:, None])
    q_true, qdot_true = standard_closed_form(t)
    np.testing.assert_allclose(p[:, 0], V0 / np.sqrt(1.0 - V0 ** 2), rtol=1e-12)   # p0 = gamma m qdot0
    np.testing.assert_allclose(q, q_true, rtol=0, atol=1e-9)
    np.testing.assert_allclose(qdot, qdot_true, rtol=0, atol=1e-9)
    assert np.all(np.abs(qdot) < 1.0)
    assert np.ptp(p, axis=1).min() > 1.0   # the field moves every momentum (the velocity near c barely moves)
    # M^-1 p: the system has no mass matrix; its rest mass (d2L/dqdot2 at rest, 1) gives gamma qdot
    with pytest.raises(NotQuadraticError):
        s.mass_matrix(Q0)
    rest_mass = s.velocity_hessian(Q0, np.zeros_like(V0))[0, 0, 0]
    assert rest_mass == pytest.approx(1.0)
    wrong = p / rest_mass
    assert np.abs(wrong).max() > 20.0   # faster than light
    assert np.abs(wrong - qdot_true).max() > 10.0


def test_a_quadratic_kinetic_energy_has_dh_dp_equal_to_m_inverse_p():
    """The pendulum with m l^2 = 0.5: H = p^2 / (2 m l^2) - m g l cos q."""
    m, l, g = 2.0, 0.5, 3.0
    s = systems.get("pendulum", m=m, l=l, g=g)

    def exact_h(q, p, extra):
        return p / (m * l ** 2), -m * g * l * np.sin(q)

    q0, qd0 = np.array([[0.3], [-1.0], [2.0]]), np.array([[1.0], [-2.0], [0.5]])
    t = np.linspace(0.0, 2.0, 41)
    q, p = canonical_rollout(exact_h, s, q0, qd0, t, 0.01)
    qdot = velocity(exact_h, q, p)
    m_inv_p = np.linalg.solve(s.mass_matrix(q), p[..., None])[..., 0]
    np.testing.assert_allclose(qdot, m_inv_p, rtol=1e-12, atol=1e-12)
    q_true, qd_true = lagbench.systems.trajectories.integrate(s, q0, qd0, t)
    np.testing.assert_allclose(q, q_true, atol=1e-7)   # RK4 at 0.01: ~2e-8
    np.testing.assert_allclose(qdot, qd_true, atol=1e-7)


def test_a_rollout_that_diverges_is_nan_from_then_on():
    s = systems.get("spring")

    def blows_up(q, p, extra):
        return p, 1e200 * p ** 3

    q, p = canonical_rollout(blows_up, s, np.zeros((2, 1)), np.array([[0.0], [1.0]]), np.linspace(0, 1, 11), 0.1)
    qdot = velocity(blows_up, q, p)
    assert np.all(np.isfinite(qdot[0])) and np.isnan(qdot[1, -1]).all() and np.isnan(q[1, -1]).all()


def _unit(claim, label):
    unit = next(u for u in plan("smoke", claims=[claim], frameworks=("torch",)) if u.entry.label == label)
    return unit, unit.protocol()


def _context(claim, label, model_of):
    unit, p = _unit(claim, label)
    c = CLAIMS[claim]
    return Context(claim=c, entry=unit.entry, framework="torch", spec=unit.spec(), params=None, protocol=p,
                   profile="smoke", cfg=c.evaluation_config("smoke"), model=model_of(system_of(p)))


class PaperRelativisticH:
    """The exact H of the paper's L = (1 - qdot^2)^(-1/2) - 1 + g q, whose p = qdot (1 - qdot^2)^(-3/2) has no
    closed-form inverse: dH/dp = qdot(p) by bisection (p is increasing in qdot), -dH/dq = g (the extra input)."""

    def __init__(self, s):
        self.s = s

    def time_derivative(self, q, p, extra=None):
        lo, hi = np.full_like(p, -1.0), np.full_like(p, 1.0)
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            below = mid * (1.0 - mid ** 2) ** -1.5 < p
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        return 0.5 * (lo + hi), np.broadcast_to(extra[:, :1], p.shape).copy()


def test_claim_3s_canonical_hnn_short_rollout_from_an_exact_h_retraces_the_truth():
    a = EVALUATIONS["heldout_trajectories"](_context("rel_coords", "hnn_qp", PaperRelativisticH)).arrays
    assert np.abs(a["qdot_true"]).max() > 0.9   # the smoke draw reaches high speed
    np.testing.assert_allclose(a["qdot_pred"], a["qdot_true"], atol=1e-9)
    np.testing.assert_allclose(a["q_pred"], a["q_true"], atol=1e-9)


class PendulumH:
    """The exact H of claim 10's pendulum (m = l = 1, g = 3): p^2 / 2 - 3 cos q."""

    def __init__(self, s):
        assert s.params["m"] == s.params["l"] == 1.0 and s.params["g"] == 3.0

    def time_derivative(self, q, p, extra=None):
        return p, -3.0 * np.sin(q)


def test_claim_10s_energy_rollout_from_an_exact_h_conserves_energy():
    out = EVALUATIONS["energy_rollout"](_context("hnn_energy", "hnn_pendulum", PendulumH))
    assert out.metrics["energy_err_max"] < 1e-6
    assert out.metrics["rollout_gmean_err"] < 1e-6
    np.testing.assert_allclose(out.arrays["q_pred"], out.arrays["q_true"], atol=1e-6)


@pytest.mark.parametrize("name, kw", [("relativistic", {"g": G}), ("relativistic_standard", {"g": G}),
                                      ("double_pendulum", {}), ("pendulum", {})])
def test_the_state_velocity_inverts_the_momentum_map(name, kw):
    s = systems.get(name)
    if s.dof == 1:
        q, qdot = Q0, V0
    else:
        st = s.sample_states(3, np.random.default_rng(0))
        q, qdot = st["q"], st["qdot"]
    p = s.canonical_momentum(q, qdot, backend="numpy", **kw)
    np.testing.assert_allclose(state_velocity(s, q, p, kw), qdot, rtol=1e-10, atol=1e-12)
    # (B, T, dof) along trajectories, a per-sample parameter (B,) of each
    np.testing.assert_allclose(state_velocity(s, q[:, None].repeat(2, 1), p[:, None].repeat(2, 1), kw),
                               qdot[:, None].repeat(2, 1), rtol=1e-10, atol=1e-12)
    bad = p.copy()
    bad[0] = np.nan
    assert np.isnan(state_velocity(s, q, bad, kw)[0]).all()


class TwiceTheVelocity(PendulumH):
    """The pendulum's H with the mass halved: dH/dp = 2 p, twice the true velocity of the state."""

    def time_derivative(self, q, p, extra=None):
        return 2.0 * p, -3.0 * np.sin(q)


def test_the_energy_rollout_reads_the_true_energy_of_the_predicted_state_not_the_learned_velocity():
    from lagbench.replication.evaluation.routines import _model_rollout

    ctx = _context("hnn_energy", "hnn_pendulum", TwiceTheVelocity)
    s = system_of(ctx.protocol)
    q0, qd0, t = np.array([[0.3], [-1.0]]), np.array([[1.0], [0.5]]), np.linspace(0.0, 1.0, 11)
    q, qd = _model_rollout(ctx, s, q0, qd0, t)
    _, p = canonical_rollout(ctx.model.time_derivative, s, q0, qd0, t, ctx.cfg["dt"])
    np.testing.assert_allclose(qd, p, rtol=1e-12)    # m = l = 1: the true velocity of (q, p) is p, not 2 p
    energy = s.energy(q, qd, backend="numpy")
    np.testing.assert_allclose(energy, p[..., 0] ** 2 / 2 - 3.0 * np.cos(q[..., 0]), rtol=1e-12)   # H_true(q, p)
