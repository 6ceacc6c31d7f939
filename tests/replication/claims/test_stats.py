"""The intervals the verdicts read (`replication.claims.stats`), against independent references: the
Hodges-Lehmann interval against the exact Mann-Whitney test it is the dual of (scipy), the U distribution
against enumeration, and the seed counts of the power rule against their binomial coefficients."""
import itertools
import math

import numpy as np
import pytest
from scipy.stats import mannwhitneyu

from lagbench.replication.claims.stats import (
    Stat,
    _u_counts,
    hodges_lehmann,
    ratio_interval,
    seeds_needed,
    wilson,
)


@pytest.mark.parametrize("m, n", [(1, 1), (2, 3), (3, 3), (4, 2)])
def test_u_distribution_matches_enumeration(m, n):
    counts = [0] * (m * n + 1)
    for xs in itertools.combinations(range(m + n), m):   # the ranks the x's take
        u = sum(1 for x in xs for y in set(range(m + n)) - set(xs) if x > y)
        counts[u] += 1
    assert list(_u_counts(m, n)) == counts


@pytest.mark.parametrize("seed", range(12))
def test_hodges_lehmann_interval_excludes_one_exactly_when_the_exact_test_rejects(seed):
    rng = np.random.default_rng(seed)
    m, n = int(rng.integers(4, 9)), int(rng.integers(4, 9))
    x = 10 ** rng.normal(0.0, 0.3, m)
    y = 10 ** rng.normal(rng.uniform(-0.6, 0.6), 0.3, n)
    alpha = 0.05
    iv = hodges_lehmann(x, y, alpha, "x/y")
    p = mannwhitneyu(x, y, alternative="two-sided", method="exact").pvalue
    assert (iv.hi < 1 or iv.lo > 1) == (p <= alpha), (iv, p)
    assert iv.lo <= iv.point <= iv.hi


def test_hodges_lehmann_counts_never_as_slowest_and_two_nevers_as_a_tie():
    inf = math.inf
    iv = hodges_lehmann([1e3] * 8, [inf] * 8, 0.05, "x/y")
    assert iv.point == 0.0 and iv.hi == 0.0
    iv = hodges_lehmann([inf] * 8, [inf] * 8, 0.05, "x/y")
    assert iv.point == 1.0 and iv.lo == 1.0 and iv.hi == 1.0


def test_too_few_seeds_give_an_unbounded_interval():
    iv = hodges_lehmann([1.0, 2.0], [10.0, 20.0], 0.05, "x/y")
    assert iv.lo == 0.0 and iv.hi == math.inf and "too few seeds" in iv.method


def test_ratio_interval_is_welchs_t_on_log_ratios_with_the_seed_range_beside_it():
    from scipy.stats import ttest_ind

    a, b = (1.0, 2.0, 1.5), (4.0, 8.0, 5.0)
    iv = ratio_interval(Stat.of(a), Stat.of(b), "a/b")
    assert iv.seed_range == (1 / 8, 2 / 4) and iv.level == 0.9 and iv.seeds == (3, 3)
    la, lb = np.log10(a), np.log10(b)
    assert iv.point == pytest.approx(10 ** (la.mean() - lb.mean()))
    # the interval's ends are where Welch's two-sided test of the log shift rejects at exactly 10 %
    for end in (iv.lo, iv.hi):
        p = ttest_ind(la - np.log10(end), lb, equal_var=False).pvalue
        assert p == pytest.approx(0.10, abs=1e-6)
    iv = ratio_interval(Stat.of([1.0, math.inf]), Stat.of([math.inf]), "a/b")
    assert iv.seed_range == (0.0, 1.0) and (iv.lo, iv.hi) == (0.0, math.inf)      # one seed: no interval
    iv = ratio_interval(Stat.of([1.0, 1.2, math.inf]), Stat.of([5.0, 6.0, 7.0]), "a/b")
    assert "Hodges-Lehmann" in iv.method and iv.hi == math.inf                     # a diverged seed ranks last


def test_seeds_needed_is_the_first_count_whose_complete_separation_has_the_margin():
    for k in (1, 3, 5):
        n = seeds_needed(0.05, k)
        assert 2 / math.comb(2 * n, n) <= 0.05 / k / 10 < 2 / math.comb(2 * n - 2, n - 1)
    assert seeds_needed(0.05, 3) == 7 and seeds_needed(0.05, 5) == 7


def test_wilson_interval_matches_reference_values():
    lo, hi = wilson(0, 10)
    assert lo == 0.0 and abs(hi - 0.2775) < 1e-4      # the textbook 0/10 upper bound
    lo, hi = wilson(5, 10)
    assert abs(lo - 0.2366) < 1e-4 and abs(hi - 0.7634) < 1e-4
