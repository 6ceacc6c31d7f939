"""speedstudy.latency.interleaved_rates: each fn gets about the same share of the time, so a fast
fn beside a slow one gets many timed windows (not as few as the slow one), and the rates come out in
the right order. Counts calls, asserts no wall-clock figure."""
import time

from lagbench.speedstudy.latency import interleaved_rates


def test_fast_fn_gets_many_windows_beside_a_slow_one():
    n = {"slow": 0, "fast": 0}

    def slow():
        n["slow"] += 1
        time.sleep(0.002)

    def fast():
        n["fast"] += 1
    rates = interleaved_rates({"slow": slow, "fast": fast}, seconds=0.3, calls=5, slice_s=0.05)
    assert rates["fast"] > rates["slow"]
    assert n["fast"] >= 20 * n["slow"]  # one window per turn would give both the same count
