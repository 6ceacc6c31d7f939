"""Pilot (not the fit's behaviour): an acceleration loss consistent with the derivative filter, for DeLaN.

The Savitzky-Golay estimate of q-double-dot at a frame is a linear filter of the recorded positions, and by
summation by parts the same as a smoothing kernel C (window - 2 taps, summing to 1) applied to q-double-dot over
the window, up to the central second difference's h^2 q''''/12. The fit's acceleration loss compares the
estimate with the model's q-double-dot at the frame alone, so the model learns the filter's bias (and its part
odd in q-dot moves the friction). The filtered loss compares the estimate with C applied to the model's
q-double-dot at the window's frames, (q, qdot) as recorded and estimated there. Two arms, the same in all else
(the fit's DeLaN protocol: 8 000 steps, batch 256 rows, MSE, L2 1e-5, constant rate 0.009; the rows whose
kernel lies inside their trajectory; init seed 0): `plain` (the fit's loss) and `filtered`. Printed: the
friction b / c (c the least-squares factor of the learned mass matrix against the true one), the mass matrix's
relative residual, and the rms error of q-double-dot against the exact dynamics (friction 0.2) at the test
file's rows, as a fraction of the exact q-double-dot's rms.

    python docs/lab/recording_defaults/filtered_loss_pilot.py OUT/s0-delan [plain|filtered ...] [seed=N]
    (a run.sh-style fit folder of `lagbench fit --model delan`: its prepared training and test rows and spec)
"""
import glob
import json
import sys
import time

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
from scipy.signal import savgol_coeffs

import lagbench.models.jax
from lagbench import systems
from lagbench.files import user_data
from lagbench.models import init_params
from lagbench.models.spec import ModelSpec

EXACT = systems.registry.get("double_pendulum", friction=0.0)
TRUE_FRICTION = 0.2


def kernel(window: int) -> np.ndarray:
    c = savgol_coeffs(window, 3, deriv=2, delta=1.0, use="dot")
    k = np.cumsum(np.cumsum(c))[:-2]   # c = k convolved with (1, -2, 1)
    assert np.allclose(np.convolve(k, [1, -2, 1]), c, atol=1e-10) and np.isclose(k.sum(), 1.0)
    return k


def neighbours(r: dict, taps: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows, (rows, taps) indices of each row's frames -taps//2 .. taps//2 in its trajectory) for the rows
    whose every such frame is a row."""
    t, traj = np.asarray(r["t"], np.float64), np.asarray(r["traj"])
    h = np.median(np.diff(t)[np.diff(t) > 0])
    half, out = taps // 2, []
    for k in np.unique(traj):
        s = np.flatnonzero(traj == k)
        pos = {f: i for f, i in zip(np.rint((t[s] - t[s][0]) / h).astype(int), s, strict=True)}
        for f, i in pos.items():
            nb = [pos.get(f + j) for j in range(-half, half + 1)]
            if None not in nb:
                out.append((i, nb))
    return np.array([i for i, _ in out]), np.array([nb for _, nb in out])


def train(spec, arm, q, qd, qdd, rows, nbs, k, steps=8000, batch=256, lr=0.009, l2=1e-5, seed=0):
    model = lagbench.models.jax.build(spec, init_params(spec, seed=seed))
    opt = optax.adam(lr)
    state = opt.init(eqx.filter(model, eqx.is_inexact_array))
    q, qd, qdd, kj = (jnp.asarray(x, jnp.float32) for x in (q, qd, qdd, k))

    def loss_fn(m, idx):
        target = qdd[rows[idx]]
        if arm == "plain":
            pred = m.acceleration(q[rows[idx]], qd[rows[idx]])
        else:
            nb = nbs[idx]                                     # (B, taps)
            a = m.acceleration(q[nb].reshape(-1, q.shape[1]), qd[nb].reshape(-1, q.shape[1]))
            pred = jnp.einsum("k,bkd->bd", kj, a.reshape(nb.shape[0], nb.shape[1], -1))
        loss = ((pred - target) ** 2).sum(-1).mean()
        leaves = jax.tree_util.tree_leaves(eqx.filter(m, eqx.is_inexact_array))
        return loss + l2 * sum(jnp.sum(p * p) for p in leaves)

    @eqx.filter_jit
    def step(m, s, idx):
        loss, g = eqx.filter_value_and_grad(loss_fn)(m, idx)
        updates, s = opt.update(g, s, eqx.filter(m, eqx.is_inexact_array))
        return eqx.apply_updates(m, updates), s, loss

    rows, nbs = jnp.asarray(rows), jnp.asarray(nbs)
    rng = np.random.default_rng(seed)
    for _ in range(steps):
        model, state, loss = step(model, state, jnp.asarray(rng.integers(0, len(rows), batch)))
    return model, float(loss)


def judge(model, test: dict) -> dict:
    p = lagbench.models.jax.to_params(model)
    b = np.log1p(np.exp(np.asarray(p["dissipation.raw"], np.float64)))
    q = np.asarray(test["q"], np.float64)[:4000]
    qd = np.asarray(test["qdot"], np.float64)[:4000]
    m_true = np.asarray(EXACT.mass_matrix(q))
    m = np.asarray(model.mass_matrix(jnp.asarray(q, jnp.float32)), np.float64)
    c = float(np.sum(m * m_true) / np.sum(m_true * m_true))
    exact = np.asarray(EXACT.acceleration(q, qd)) - np.einsum("nij,nj->ni", np.linalg.inv(m_true), TRUE_FRICTION * qd)
    pred = np.asarray(model.acceleration(jnp.asarray(q, jnp.float32), jnp.asarray(qd, jnp.float32)), np.float64)
    return {"friction": (b / c).round(4).tolist(), "mass_residual": round(float(np.linalg.norm(m - c * m_true)
            / np.linalg.norm(m)), 4), "error_vs_exact": round(float(np.sqrt(((pred - exact) ** 2).mean()
            / (exact ** 2).mean())), 4)}


def main(folder: str, arms: list[str], seed: int = 0) -> None:
    result = json.loads(open(glob.glob(folder + "/units/fit/jax/*/seed0/result.json")[0]).read())
    spec = ModelSpec.from_dict(result["model_spec"])
    window = result["eval_config"]["derivatives"]["window"]
    r = user_data.rows(glob.glob(folder + "/data/train-fit-*.csv")[0], "train")
    test = user_data.rows(glob.glob(folder + "/data/val-test-*.csv")[0], "test")
    k = kernel(window)
    rows, nbs = neighbours(r, len(k))
    q, qd, qdd = (np.asarray(r[x], np.float64) for x in ("q", "qdot", "qddot"))
    print(f"window {window}: kernel of {len(k)} taps; {len(rows)} of {len(q)} training rows have it whole", flush=True)
    for arm in arms:
        t0 = time.time()
        model, loss = train(spec, arm, q, qd, qdd, rows, nbs, k, seed=seed)
        print(f"{arm}, seed {seed}: {judge(model, test)} final loss {loss:.4g}, {time.time() - t0:.0f} s", flush=True)


if __name__ == "__main__":
    args = [a for a in sys.argv[2:] if not a.startswith("seed=")]
    seeds = [int(a[5:]) for a in sys.argv[2:] if a.startswith("seed=")]
    main(sys.argv[1], args or ["plain", "filtered"], *seeds[:1])
