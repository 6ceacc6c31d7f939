"""The statistics the verdict rules read: a metric over seeds, and the intervals of a comparison.

- ``Stat``: a metric's values over seeds (+inf = a diverged rollout; a NaN or missing seed is counted in
  ``dropped``, never silently lost).
- ``ratio_interval(a, b, level)``: the ratio of two models' metric (their seeds are independent runs) with
  its two-sided confidence interval at ``level`` (``LEVEL``, 90 %: each side a one-sided 5 % test). With
  every value finite and positive, Welch's t interval on log10(a) - log10(b) (errors and times spread
  multiplicatively; the t quantile and 1/sqrt(n) widen it as seeds fall, and one seed a model gives none);
  with a diverged (+inf) or zero value, the exact rank interval (``hodges_lehmann``, +inf ranking last),
  which at 2 seeds a model is unbounded; a NaN seed gives no interval. The range of a_i / b_j over every
  seed pair is kept beside it as a description (``range_lo``, ``range_hi``), never decided on.
- ``hodges_lehmann(x, y)``: the shift of log10(x) against log10(y) (the median of every pairwise
  difference; +inf for a run that never got there, two such runs tie) with its exact distribution-free
  interval from the Mann-Whitney U distribution (Lehmann 1975, ch. 2): the k-th smallest and largest
  differences, k the largest count with P(U < k) <= alpha / 2.
- ``seeds_needed(alpha, k, margin)``: the seed count a pooled claim needs (its power rule, below).
- ``wilson(k, n)``: the 95 % Wilson interval of a share.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache

from scipy.stats import t as student_t

# the two-sided confidence of every interval an ordering or a similarity is decided on
LEVEL = 0.90


@dataclass(frozen=True)
class Stat:
    """A metric's values over seeds (+inf = diverged), and how many seeds had none (NaN or missing).
    ``mean`` is +inf if any value is."""

    values: tuple
    dropped: int = 0

    @classmethod
    def of(cls, values) -> Stat:
        vals = list(values)
        vs = tuple(float(x) for x in vals if x is not None and not math.isnan(float(x)))
        if not vs:
            raise ValueError("Stat.of: no finite or infinite value (all missing or NaN)")
        return cls(vs, len(vals) - len(vs))

    @property
    def n(self) -> int:
        return len(self.values)

    @property
    def mean(self) -> float:
        return math.inf if any(math.isinf(x) for x in self.values) else sum(self.values) / self.n

    @property
    def std(self) -> float:
        if self.n < 2:
            return 0.0
        if any(math.isinf(x) for x in self.values):
            return math.inf if not all(math.isinf(x) for x in self.values) else 0.0
        m = self.mean
        return math.sqrt(sum((x - m) ** 2 for x in self.values) / (self.n - 1))

    @property
    def lo(self) -> float:
        return min(self.values)

    @property
    def hi(self) -> float:
        return max(self.values)

    def __format__(self, spec) -> str:
        text = f"{self.mean:.3g}" if self.n == 1 else f"{self.mean:.3g} [{self.lo:.3g}, {self.hi:.3g}]"
        return text + (f" ({self.dropped} NaN seed{'s' if self.dropped > 1 else ''})" if self.dropped else "")


def separated(a: Stat, b: Stat) -> bool:
    """a lies below b beyond the seed spread: every seed of a below every seed of b."""
    return a.hi < b.lo


def _ratio(x: float, y: float) -> float:
    """x / y for non-negative errors: two diverged (or two zero) values tie at 1, x / 0 is +inf."""
    if (math.isinf(x) and math.isinf(y)) or (x == 0 and y == 0):
        return 1.0
    if y == 0 or math.isinf(x):
        return math.inf
    return x / y


@dataclass(frozen=True)
class Interval:
    """A point estimate with its interval, its two-sided confidence ``level`` (None: a plain range, not a
    confidence interval), the seeds it rests on, the range over seed pairs it describes, and how it was made."""

    what: str
    point: float
    lo: float
    hi: float
    method: str
    level: float | None = None
    seeds: tuple = ()                       # the seed count of each side
    seed_range: tuple = field(default=())   # (lo, hi) of the value over every seed (pair), a description

    def to_dict(self) -> dict:
        d = {"what": self.what, "point": self.point, "lo": self.lo, "hi": self.hi, "method": self.method,
             "level": self.level, "seeds": list(self.seeds)}
        if self.seed_range:
            d["range_lo"], d["range_hi"] = self.seed_range
        return d

    def __str__(self) -> str:
        rng = f"; seed pairs {self.seed_range[0]:.3g}-{self.seed_range[1]:.3g}" if self.seed_range else ""
        return f"{self.what} {self.point:.3g} [{self.lo:.3g}, {self.hi:.3g}] ({self.method}{rng})"


def _log_t(a: tuple, b: tuple, level: float) -> tuple[float, float, float, float]:
    """(point, lo, hi, df) of 10^(mean log10 a - mean log10 b) with Welch's t interval at ``level``."""
    la, lb = [math.log10(x) for x in a], [math.log10(x) for x in b]
    ma, mb = sum(la) / len(la), sum(lb) / len(lb)
    va = sum((x - ma) ** 2 for x in la) / (len(la) - 1) / len(la)
    vb = sum((x - mb) ** 2 for x in lb) / (len(lb) - 1) / len(lb)
    d, se = ma - mb, math.sqrt(va + vb)
    if se == 0:
        return 10.0 ** d, 10.0 ** d, 10.0 ** d, math.inf
    df = (va + vb) ** 2 / (va ** 2 / (len(la) - 1) + vb ** 2 / (len(lb) - 1))
    half = float(student_t.ppf(0.5 + level / 2, df)) * se
    return 10.0 ** d, 10.0 ** (d - half), 10.0 ** (d + half), df


def ratio_interval(a: Stat, b: Stat, what: str, level: float = LEVEL) -> Interval:
    """a over b with its confidence interval at ``level`` (the module docstring says which interval)."""
    pairs = [_ratio(x, y) for x in a.values for y in b.values]
    rng, seeds = (min(pairs), max(pairs)), (a.n + a.dropped, b.n + b.dropped)
    if a.dropped or b.dropped:
        return Interval(what, _ratio(a.mean, b.mean), 0.0, math.inf, "no interval: a seed's value is NaN",
                        level, seeds, rng)
    if a.n < 2 or b.n < 2:
        return Interval(what, _ratio(a.mean, b.mean), 0.0, math.inf, "no interval: one seed", level, seeds, rng)
    if all(0 < x < math.inf for x in (*a.values, *b.values)):
        point, lo, hi, df = _log_t(a.values, b.values, level)
        how = f"Welch t on log ratios, df {df:.3g}" if math.isfinite(df) else "no spread over seeds"
        return Interval(what, point, lo, hi, f"{100 * level:g} % interval, {how}", level, seeds, rng)
    hl = hodges_lehmann(a.values, b.values, round(1 - level, 12), what)
    return Interval(what, hl.point, hl.lo, hl.hi, hl.method + " (a diverged or zero seed)", level, seeds, rng)


@cache
def _u_counts(m: int, n: int) -> tuple:
    """The number of orderings of m x's and n y's giving each U = #(x_i > y_j), u = 0..mn (no ties)."""
    if m == 0 or n == 0:
        return (1,)
    a, b = _u_counts(m - 1, n), _u_counts(m, n - 1)
    out = [0] * (m * n + 1)
    for u, c in enumerate(b):          # the largest value is a y: it adds nothing to U
        out[u] += c
    for u, c in enumerate(a):          # the largest value is an x: it exceeds all n y's
        out[u + n] += c
    return tuple(out)


def u_lower_tail(m: int, n: int, k: int) -> float:
    """P(U < k) under no difference, exactly."""
    c = _u_counts(m, n)
    return sum(c[:max(k, 0)]) / math.comb(m + n, m)


def hl_rank(m: int, n: int, alpha: float) -> int:
    """The largest k with P(U < k) <= alpha / 2 (0: no interval this narrow exists at these sizes)."""
    k = 0
    while k < m * n and u_lower_tail(m, n, k + 1) <= alpha / 2:
        k += 1
    return k


def _log10(x: float) -> float:
    return math.inf if math.isinf(x) else math.log10(max(x, 1e-300))


def hodges_lehmann(x, y, alpha: float, what: str) -> Interval:
    """The shift of log10(x) against log10(y) as a ratio 10^shift, with its two-sided 1 - alpha interval
    (values +inf count as never; two of them tie). Below 1: x tends to be smaller."""
    d = []
    for a in x:
        for b in y:
            la, lb = _log10(a), _log10(b)
            d.append(0.0 if math.isinf(la) and math.isinf(lb) else la - lb)
    d.sort()
    n = len(d)
    mid = (d[(n - 1) // 2] + d[n // 2]) / 2 if n else 0.0
    k = hl_rank(len(x), len(y), alpha)
    lo, hi = (d[k - 1], d[n - k]) if k >= 1 else (-math.inf, math.inf)

    def ratio(s):
        return math.inf if s == math.inf else 0.0 if s == -math.inf else 10.0 ** s
    return Interval(what, ratio(mid) if math.isfinite(mid) or n else 1.0, ratio(lo), ratio(hi),
                    f"Hodges-Lehmann, exact {100 * (1 - alpha):.3g} % interval" + ("" if k else ": too few seeds"),
                    1 - alpha, (len(x), len(y)))


def seeds_needed(alpha: float, k: int, margin: float = 10.0) -> int:
    """The power rule of the pooled claims: the smallest n seeds a model such that a complete separation
    of two models gives a two-sided exact p at least ``margin`` times below alpha / k (the Bonferroni level
    over k rivals), so that a clear difference can reach the level even with a few crossings."""
    n = 1
    while 2 / math.comb(2 * n, n) > alpha / k / margin:
        n += 1
    return n


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson score interval (95 % at z = 1.96) of a share k/n."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    mid = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, mid - half), min(1.0, mid + half)
