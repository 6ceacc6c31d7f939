"""The Euler-Lagrange routine: exact Lagrangians recover known accelerations in both formulations and
frameworks, fast equals paper where the velocity Hessian is well conditioned, and singular Hessians
take the counted pinv fallback without letting a NaN out."""
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import torch
from models_testkit import assert_rel, make_inputs, spec_params, to_jax, to_torch

import lagbench.models.jax
import lagbench.models.jax.lnn as jlnn
import lagbench.models.torch
import lagbench.models.torch.lnn as tlnn

G = 9.8


class _JittedEL:
    """models.jax.lnn with euler_lagrange(_info) compiled (eqx.filter_jit): faster tests."""
    euler_lagrange_info = staticmethod(eqx.filter_jit(jlnn.euler_lagrange_info))
    euler_lagrange = staticmethod(eqx.filter_jit(jlnn.euler_lagrange))


FW = {"jax": (_JittedEL, jnp, jnp.asarray), "torch": (tlnn, torch, torch.tensor)}


def double_pendulum_lagrangian(xp):
    """m1 = m2 = l1 = l2 = 1 (the LNN code's physics.py), angles from the downward vertical."""
    def lagrangian(q, qdot):
        t1, t2, w1, w2 = q[..., 0], q[..., 1], qdot[..., 0], qdot[..., 1]
        kinetic = w1 ** 2 + 0.5 * w2 ** 2 + w1 * w2 * xp.cos(t1 - t2)
        return kinetic + 2 * G * xp.cos(t1) + G * xp.cos(t2)
    return lagrangian


def assencio_acceleration(q, qdot):
    """The closed form of the original code's analytical_fn (reference section 2), NumPy."""
    t1, t2, w1, w2 = q[..., 0], q[..., 1], qdot[..., 0], qdot[..., 1]
    a1, a2 = 0.5 * np.cos(t1 - t2), np.cos(t1 - t2)
    f1 = -0.5 * w2 ** 2 * np.sin(t1 - t2) - G * np.sin(t1)
    f2 = w1 ** 2 * np.sin(t1 - t2) - G * np.sin(t2)
    return np.stack([(f1 - a1 * f2) / (1 - a1 * a2), (f2 - a2 * f1) / (1 - a1 * a2)], axis=-1)


def _states(batch=32, d=2, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 2 * np.pi, (batch, d)), rng.uniform(-10, 10, (batch, d))


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("formulation", ["fast", "paper"])
def test_exact_double_pendulum_lagrangian_recovers_the_closed_form(fw, formulation):
    lnn, xp, arr = FW[fw]
    q, qdot = _states()
    got, n_bad = lnn.euler_lagrange_info(double_pendulum_lagrangian(xp), arr(q), arr(qdot), formulation)
    assert_rel(np.asarray(got), assencio_acceleration(q, qdot), "float64", "double pendulum", factor=10)
    assert int(n_bad) == 0


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_free_fall_gives_minus_g_appendix_b(fw):
    lnn, xp, arr = FW[fw]
    q, qdot = _states(batch=5)
    free_fall = lambda q, qd: 0.5 * xp.sum(qd ** 2, -1) - G * q[..., 0]  # noqa: E731
    for formulation in ("fast", "paper"):
        got = np.asarray(lnn.euler_lagrange(free_fall, arr(q), arr(qdot), formulation))
        np.testing.assert_allclose(got, np.tile([-G, 0.0], (5, 1)), atol=1e-12)


def test_system_registry_accelerations_if_available():
    systems = pytest.importorskip("lagbench.systems")
    if not hasattr(systems, "get"):
        pytest.skip("systems.get not available yet")
    q, qdot = _states()
    truth = systems.get("double_pendulum").acceleration(q, qdot, backend="numpy")
    got = tlnn.euler_lagrange(double_pendulum_lagrangian(torch), torch.tensor(q), torch.tensor(qdot), "fast")
    assert_rel(got.numpy(), truth, "float64", "systems double pendulum", factor=10)


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_fast_equals_paper_where_the_hessian_is_well_conditioned(fw):
    spec, params = spec_params(kind="lnn", dof=3, dtype="float64", init="xavier")
    x = make_inputs(spec, batch=24, seed=5)
    build, conv = (lagbench.models.jax.build, to_jax) if fw == "jax" else (lagbench.models.torch.build, to_torch)
    model, xs = build(spec, params), conv(x)
    L = model.lagrangian
    fast, n_bad = FW[fw][0].euler_lagrange_info(L, xs["q"], xs["qdot"], "fast")
    paper = FW[fw][0].euler_lagrange(L, xs["q"], xs["qdot"], "paper")
    hess = np.asarray(model.velocity_hessian(xs["q"], xs["qdot"]).tolist())
    good = np.linalg.cond(hess) < 1e6
    assert good.sum() >= 12 and int(n_bad) == 0
    assert_rel(np.asarray(fast.tolist())[good], np.asarray(paper.tolist())[good], "float64", "fast vs paper", factor=100)


def _half_singular(xp):
    """L = 1/2 q1 qdot1^2 + 1/2 qdot2^2 - 1/2 q2^2: the Hessian diag(q1, 1) is singular where q1 = 0."""
    return lambda q, qd: 0.5 * q[..., 0] * qd[..., 0] ** 2 + 0.5 * qd[..., 1] ** 2 - 0.5 * q[..., 1] ** 2


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_singular_hessians_are_counted_and_take_pinv(fw):
    lnn, xp, arr = FW[fw]
    q, qdot = _states(batch=8, seed=7)
    q[[1, 4, 6], 0] = 0.0
    fast, n_bad = lnn.euler_lagrange_info(_half_singular(xp), arr(q), arr(qdot), "fast")
    paper = lnn.euler_lagrange(_half_singular(xp), arr(q), arr(qdot), "paper")
    assert int(n_bad) == 3
    fast, paper = np.asarray(fast.tolist()), np.asarray(paper.tolist())
    assert np.all(np.isfinite(fast))
    assert_rel(fast, paper, "float64", "fallback equals pinv", factor=100)
    np.testing.assert_allclose(fast[[1, 4, 6], 0], 0.0)     # pinv drops the null direction
    np.testing.assert_allclose(fast[:, 1], -q[:, 1])         # the regular coordinate is exact


def test_fallback_gradients_stay_finite():
    q, qdot = _states(batch=6, seed=8)
    q[2, 0] = 0.0

    def jax_loss(a):
        L = lambda q, qd: a * _half_singular(jnp)(q, qd)  # noqa: E731
        return jnp.sum(jlnn.euler_lagrange(L, jnp.asarray(q), jnp.asarray(qdot)))
    assert np.isfinite(float(jax.jit(jax.grad(jax_loss))(1.5)))
    a = torch.tensor(1.5, dtype=torch.float64, requires_grad=True)
    L = lambda q, qd: a * _half_singular(torch)(q, qd)  # noqa: E731
    tlnn.euler_lagrange(L, torch.tensor(q), torch.tensor(qdot)).sum().backward()
    assert torch.isfinite(a.grad)


@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_relu_lnn_has_a_zero_hessian_everywhere_and_every_sample_falls_back(fw):
    spec, params = spec_params(kind="lnn", dof=2, dtype="float64", activation="relu")
    x = make_inputs(spec, batch=10)
    build, conv = (lagbench.models.jax.build, to_jax) if fw == "jax" else (lagbench.models.torch.build, to_torch)
    xs = conv(x)
    qddot, n_bad = build(spec, params).acceleration_info(xs["q"], xs["qdot"])
    assert int(n_bad) == 10
    assert np.all(np.isfinite(np.asarray(qddot.tolist())))


@pytest.mark.parametrize("fw", ["jax", "torch"])
@pytest.mark.parametrize("activation, extra, scale", [("softplus", 0, None), ("tanh", 2, [0.5, 2.0, 1.5, 0.3, 1.0, 1.0]),
                                                      ("relu3", 0, [1.0, 2.0, 0.5, 3.0])])
def test_hand_written_fast_terms_equal_forward_over_reverse(fw, activation, extra, scale):
    """The LNN's own fast path (`mlp_derivatives`) against the generic `fast_terms` of its Lagrangian."""
    spec, params = spec_params(kind="lnn", dof=2, dtype="float64", init="xavier", activation=activation,
                               extra_inputs=extra, input_scale=scale, angle_wrap=True)
    x = make_inputs(spec, batch=16, seed=3)
    build, conv, lib = (lagbench.models.jax.build, to_jax, jlnn) if fw == "jax" else (lagbench.models.torch.build, to_torch, tlnn)
    model, xs = build(spec, params), conv(x)
    e = xs["extra"] if extra else None
    hand = model._fast_terms(xs["q"], xs["qdot"], e)
    generic = lib.fast_terms(model._lagrangian, xs["q"], xs["qdot"], e)
    for a, b, what in zip(hand, generic, ("hessian", "rhs"), strict=True):
        assert_rel(np.asarray(a.tolist()), np.asarray(b.tolist()), "float64", what)


def test_pinv_solve_by_svd_matches_pinv():
    """pinv_solve(..., by_svd=True) (the banded LGN's exported fallback) equals the torch.linalg.pinv
    form: full-rank, rank-deficient (dropped singular values), zero and non-finite matrices."""
    from lagbench.models.torch.lnn import pinv_solve

    rng = np.random.default_rng(5)
    u = torch.tensor(rng.normal(size=(4, 6, 3)))
    h = torch.stack([u[0] @ u[0].T + torch.eye(6, dtype=torch.float64),   # full rank
                     u[1] @ u[1].T,                                     # rank 3
                     torch.zeros(6, 6, dtype=torch.float64),
                     torch.full((6, 6), float("nan"), dtype=torch.float64)])
    rhs = torch.tensor(rng.normal(size=(4, 6)))
    want, got = pinv_solve(h, rhs), pinv_solve(h, rhs, by_svd=True)
    np.testing.assert_allclose(got.numpy(), want.numpy(), rtol=1e-9, atol=1e-9)
    assert torch.isnan(got[3]).all() and (got[2] == 0).all()


@pytest.mark.parametrize("orientation", [1.0, -1.0])
@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_dissipation_removes_energy_at_the_rate_of_its_rayleigh_function(fw, orientation):
    """With D = 1/2 sum b qdot^2 the learned energy E = qdot . dL/dqdot - L, oriented by s = sign(tr H), changes
    at d(sE)/dt = -sum b qdot^2 along the model's own motion (the model's Hessian and gradients,
    finite-differenced along that motion), and the acceleration is the conservative one less H^-1 s b qdot."""
    from lagbench.models import ModelSpec, init_params

    def _np(x):
        return x.detach().numpy() if hasattr(x, "detach") else np.asarray(x)

    spec = ModelSpec(kind="lnn", dof=2, hidden=(16, 16), dtype="float64", dissipation=True)
    params = init_params(spec, seed=2)
    params["dissipation.raw"] = np.array([0.4, -0.7])
    for k in ("mlp.2.weight", "mlp.2.bias"):   # the same Lagrangian, or its negative: both fit the same data
        params[k] = orientation * params[k]
    b = np.log1p(np.exp(params["dissipation.raw"]))
    conservative = ModelSpec(kind="lnn", dof=2, hidden=(16, 16), dtype="float64")
    build, conv = (lagbench.models.jax.build, jnp.asarray) if fw == "jax" else (lagbench.models.torch.build, torch.tensor)
    m = build(spec, {k: conv(v) for k, v in params.items()})
    m0 = build(conservative, {k: conv(v) for k, v in params.items() if k != "dissipation.raw"})
    rng = np.random.default_rng(0)
    q, qd = rng.normal(size=(6, 2)), rng.normal(size=(6, 2))
    qdd = _np(m.acceleration(conv(q), conv(qd)))
    hess = _np(m0.velocity_hessian(conv(q), conv(qd)))
    side = np.sign(np.trace(hess, axis1=-2, axis2=-1))[:, None]   # the force opposes the learned energy side * E
    expected = _np(m0.acceleration(conv(q), conv(qd))) - np.linalg.solve(hess, (side * b * qd)[..., None])[..., 0]
    assert_rel(qdd, expected, "float64", "dissipative acceleration")

    def energy(q_, qd_):
        lag = _np(m0.lagrangian(conv(q_), conv(qd_)))
        h = 1e-4   # qdot . dL/dqdot by central differences along qdot (L is O(10): wider steps, less rounding)
        lp, lm = (_np(m0.lagrangian(conv(q_), conv(qd_ * (1 + s * h)))) for s in (1, -1))
        return (lp - lm) / (2 * h) - lag
    dt = 1e-5   # qddot reaches 60 here: the central difference along the motion errs by O(dt^2 qddot^2)
    rate = (energy(q + dt * qd, qd + dt * qdd) - energy(q - dt * qd, qd - dt * qdd)) / (2 * dt)
    fine = np.linalg.cond(hess) < 100   # where the finite differences are accurate (not near a singular H)
    assert fine.sum() >= 4
    assert np.all(side[fine] == orientation)
    np.testing.assert_allclose((side[:, 0] * rate)[fine], -np.sum(b * qd * qd, -1)[fine], rtol=1e-4, atol=1e-6)
