"""Valid prediction time and the Lyapunov time (`replication.evaluation.valid_time`) on series with known answers."""
import numpy as np

from lagbench.replication.evaluation.valid_time import lyapunov_time, normalised_rmse, valid_time, valid_times


def test_normalised_rmse_divides_by_each_components_spread_and_counts_nan_as_infinite():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(3, 50, 2)) * np.array([1.0, 100.0])
    off = np.array([0.1, 10.0])                           # about a tenth of each component's spread
    e = normalised_rmse(z + off, z)
    np.testing.assert_allclose(e, np.sqrt(np.mean((off / z.reshape(-1, 2).std(0)) ** 2)) * np.ones((3, 50)))
    assert abs(e[0, 0] - 0.1) < 0.02
    bad = z.copy()
    bad[0, 10:] = np.nan
    assert np.isinf(normalised_rmse(bad, z)[0, 10:]).all()


def test_valid_time_is_the_first_crossing_or_the_horizon():
    t = np.linspace(0, 9, 10)
    err = np.array([[0, 0.1, 0.5, 0.1] + [0.1] * 6, [0.0] * 10])
    np.testing.assert_array_equal(valid_time(err, t, 0.4), [2.0, 9.0])


def test_lyapunov_time_of_an_exponential_separation_and_none_of_a_linear_one():
    t = np.linspace(0, 20, 401)
    grow = 1e-9 * np.exp(t / 0.5)
    linear = 1e-9 * (1 + t)
    lt = lyapunov_time(np.stack([np.minimum(grow, 1.0), linear]), t)
    assert abs(lt[0] - 0.5) < 1e-6 and np.isnan(lt[1])


def test_valid_times_against_a_perfect_and_a_useless_prediction():
    t = np.linspace(0, 10, 101)
    truth = np.stack([np.sin(t), np.cos(t)], -1)[None].repeat(2, 0)
    m, cols = valid_times(t, truth, truth, truth)
    assert m["vpt_s"] == m["chaos_floor_vpt_s"] == 10.0 and m["vpt_censored"] == 1.0 and np.isnan(m["lyapunov_time_s"])
    m, _ = valid_times(t, np.zeros_like(truth), truth, truth)
    assert m["vpt_s"] == 0.0 and m["vpt_nmse_s"] == 0.0 and set(cols) >= {"vpt_s", "lyapunov_time_s"}
