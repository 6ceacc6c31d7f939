"""The sustained crossing of `replication.studies.online` (claim 13's `t_reach_s`) on synthetic window series: a
single early dip is a first crossing but not a reach, a sustained run is reached at its first window, a run the
end of the run cuts short never counts, a window exactly at the line is at it, a NaN or +inf (diverged) window
is above it, and a run shorter than the sustain (smoke's 1 s) never reaches without failing."""
import math

import numpy as np
import pandas as pd
import pytest

from lagbench.replication.studies import online as O

WINDOW, LINE = 0.5, 0.1
ABOVE, BELOW = 1.0, 0.05


def summary(ratios, sustain: float = 5.0) -> dict:
    """The summary row of windows of WINDOW seconds with these ratios to PD alone."""
    n = len(ratios)
    w = pd.DataFrame({"t_start": WINDOW * np.arange(n), "ratio_to_pd": ratios, "track_mse": ratios,
                      "n_diverged": 0, "steps": 0})
    ticks = {"inference_us": np.ones(3), "learning_us": np.ones(3)}
    return O.summary_row(w, ticks, LINE, WINDOW, sustain)


def times(ratios, sustain: float = 5.0) -> tuple[float, float]:
    row = summary(ratios, sustain)
    return row["t_reach_s"], row["t_first_cross_s"]


def test_ten_windows_make_five_seconds_and_zero_seconds_is_the_first_crossing():
    assert O.SUSTAIN == 5.0 and O.sustain_windows(O.SUSTAIN, O.WINDOW) == 10
    assert O.sustain_windows(0.0, WINDOW) == 1 and O.sustain_windows(1.0, 0.3) == 4
    assert O.sustain_windows(1.5, 0.5) == 3   # a whole number of windows is not rounded up
    assert times([ABOVE, BELOW, ABOVE], sustain=0.0) == (1.0, 1.0)


def test_a_single_early_dip_is_a_first_crossing_but_not_reached():
    reach, first = times([BELOW] + [ABOVE] * 19)
    assert first == 0.5 and math.isnan(reach)
    reach, first = times([BELOW] * 9 + [ABOVE] * 11)   # nine windows: 4.5 s, short of 5
    assert first == 0.5 and math.isnan(reach)


def test_a_sustained_run_is_reached_at_its_first_window():
    reach, first = times([ABOVE] * 4 + [BELOW] * 10 + [ABOVE] * 6)
    assert reach == first == 2.5   # the end of window 4, the run's first
    reach, first = times([BELOW, ABOVE, ABOVE, BELOW, ABOVE] + [BELOW] * 12 + [ABOVE] * 3)
    assert first == 0.5 and reach == 3.0   # the dips do not count, the run from window 5 does


def test_a_run_cut_by_the_end_of_the_run_does_not_count_and_one_ending_there_whole_does():
    reach, first = times([ABOVE] * 15 + [BELOW] * 5)
    assert first == 8.0 and math.isnan(reach)
    reach, _ = times([ABOVE] * 10 + [BELOW] * 10)
    assert reach == 5.5


def test_windows_exactly_at_the_line_are_at_it():
    assert list(O.at_bar([LINE, LINE * (1 + 1e-12), 0.0], LINE)) == [True, False, True]
    assert times([LINE] * 10) == (0.5, 0.5)


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_nan_or_diverged_window_is_above_the_line_and_breaks_a_run(bad):
    assert not O.at_bar([bad], LINE).any()
    reach, first = times([BELOW] * 5 + [bad] + [BELOW] * 5)
    assert first == 0.5 and math.isnan(reach)
    reach, first = times([bad] + [BELOW] * 10)
    assert reach == first == 1.0


def test_a_run_shorter_than_the_sustain_never_reaches():
    reach, first = times([BELOW, BELOW])   # smoke: 1 s of learning, two windows
    assert first == 0.5 and math.isnan(reach)
    assert O.sustain_start(np.zeros(0, bool), 10) is None
