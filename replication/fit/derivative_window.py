"""`--window auto`: the Savitzky-Golay window chosen from the recording itself, for the derivative the fit's
loss trains on (q̈, or q̇ where the file gives q̈).

A wider window averages more of the recording's noise away but biases the estimate where the motion
curves within it; which window balances the two depends on the noise, the sampling rate and the motion, so
it is read off the data (`choose(pieces, polyorder, order, high) -> Choice`), one window for the whole file:

Noise (`noise(pieces)`): the standard deviation s of white noise on the differentiated signal x, per
coordinate, from the differences of order k = 3..6 of consecutive recorded samples (stencils touching a
filled frame left out): noise alone gives Δ^k x a standard deviation of s sqrt(C(2k, k)); the motion adds
about (ω h)^k x, small at a rate that resolves the motion. Each order's estimate is 1.4826 x the median
absolute deviation of its differences / sqrt(C(2k, k)) (robust to the minority of samples where the motion
is fast), and the smallest over the orders is taken: the one the motion inflates least.

Window: among the odd candidate windows (`candidates`: every odd window from polyorder + 2 to 25, then
steps of about `GROWTH`, up to `high`), the one that minimises the estimated mean squared error of the
`order`-th derivative, summed over the coordinates (as the loss sums them):

    R(w) = mean (D_w - D_ref)^2 - s^2 (|c_w - c_ref|^2 - |c_w|^2) / h^(2 order),

D_w the estimate at window w (filter coefficients c_w), D_ref a reference estimate of small bias. Since
E (D_w - D_ref)^2 = (b_w - b_ref)^2 + s^2 |c_w - c_ref|^2 / h^(2 order) for biases b, R(w) estimates
b_w^2 + s^2 |c_w|^2 / h^(2 order), the error at w, up to terms in b_ref (Mallows' C_p with an unbiased
reference in place of the truth). The reference starts as the smallest window at the same degree (least
bias, most noise) and is then, in up to `ROUNDS` rounds, the degree polyorder + 2 at the window last chosen
(a bias of higher order in the window's length, far less noise), until a window repeats: at high sampling
rates the first, noisy reference alone picks windows several times too small. Near-ties (within 1e-9 of
the target's mean square) go to the smaller window, so data without noise (exact polynomials) keep the
smallest. Checked against the true q̈ of simulated recordings with known noise in
tests/replication/fit/test_derivative_window.py.

Bounds: `high` is at most `MAX_SHARE` of the samples of the file's shortest trajectory (so the ends without a
centred window, dropped, are at most that share of it) and at least polyorder + 2 (odd). `Choice.record()`
is what a fit records (eval_config["derivatives"]); `describe(record)` says it in words.
"""
from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

AUTO = "auto"
MAX_SHARE = 1 / 3   # the widest window: this share of the shortest trajectory's samples
GROWTH = 1.08       # candidate windows above 25 grow by about this factor
ROUNDS = 8          # at most this many choices with a refined reference
ORDERS = (3, 4, 5, 6)
MAD = 1.4826        # the median absolute deviation of a normal variable is 1 / MAD standard deviations
TIE = 1e-9
TARGETS = {(2, "q"): "q̈ from q", (1, "qdot"): "q̈ from the given q̇", (1, "q"): "q̇ from q"}


@dataclass(frozen=True)
class Choice:
    window: int
    polyorder: int
    target: str          # what the window estimates: a TARGETS value
    noise: tuple         # the estimated noise s of the differentiated signal, per coordinate
    noise_rms: float     # the predicted rms error of the target at the window, from the noise
    bias_rms: float      # ... from the filter's bias (over the coordinates together)
    low: int             # the candidate windows
    high: int

    def record(self) -> dict:
        def g(x):   # 4 significant digits: a record to read, not to compute with
            return float(f"{x:.4g}")

        return {"window": self.window, "polyorder": self.polyorder, "rule": AUTO, "target": self.target,
                "noise": [g(s) for s in self.noise], "error_rms": {"noise": g(self.noise_rms), "bias": g(self.bias_rms)},
                "windows": [self.low, self.high]}


def smallest(polyorder: int) -> int:
    """The smallest valid window: odd, >= polyorder + 2."""
    return polyorder + 2 if polyorder % 2 else polyorder + 3


def highest(shortest: int, polyorder: int) -> int:
    """The widest candidate window for a file whose shortest trajectory has `shortest` samples."""
    w = int(MAX_SHARE * shortest)
    return max(smallest(polyorder), w if w % 2 else w - 1)


def candidates(polyorder: int, high: int) -> list[int]:
    out, w = [], smallest(polyorder)
    while w <= high:
        out.append(w)
        w = max(w + 2, int(w * GROWTH) // 2 * 2 + 1) if w >= 25 else w + 2
    return out or [smallest(polyorder)]


def noise(pieces) -> np.ndarray:
    """(d,): the noise s of each coordinate of the pieces' signals (see the module doc); 0 where no stencil fits.
    `pieces`: (x (T, d), h, real (T,) bool: False on filled frames)."""
    d = pieces[0][0].shape[1]
    best = np.full(d, np.inf)
    for k in ORDERS:
        diffs = []
        for x, _, real in pieces:
            if len(x) <= k:
                continue
            whole = np.convolve(real.astype(int), np.ones(k + 1, int), "valid") == k + 1
            diffs.append(np.diff(x, n=k, axis=0)[whole])
        diffs = np.concatenate(diffs) if diffs else np.empty((0, d))
        if len(diffs):
            mad = np.median(np.abs(diffs - np.median(diffs, axis=0)), axis=0)
            best = np.minimum(best, MAD * mad / np.sqrt(comb(2 * k, k)))
    return np.where(np.isfinite(best), best, 0.0)


def _filtered(x, c, h, order):
    """The estimate of coefficients c (`savgol_coeffs` at unit spacing) at spacing h, at every sample with a
    centred window (the others are not used), by FFT: the values of `savgol_filter` there, at a cost that
    hardly grows with the window."""
    from scipy.signal import fftconvolve

    return fftconvolve(x, c[:, None] / h ** order, mode="same", axes=0)


def _centred(c, n):
    out = np.zeros(n)
    out[(n - c.size) // 2:(n - c.size) // 2 + c.size] = c
    return out


def _risks(pieces, s, windows, ref, polyorder, order, margin):
    """(R(w) per window, noise part per window, target mean square) over the pieces' interior real samples."""
    from scipy.signal import savgol_coeffs

    c_ref = savgol_coeffs(*ref, deriv=order)
    used = [(x, h, np.r_[np.zeros(margin, bool), real[margin:len(x) - margin], np.zeros(margin, bool)])
            for x, h, real in pieces if len(x) > 2 * margin]
    n = max(sum(int(m.sum()) for _, _, m in used), 1)   # none (all frames filled): every R(w) 0, the smallest
    inv = sum(int(m.sum()) / h ** (2 * order) for _, h, m in used) / n   # mean of 1 / h^(2 order)
    refs = [_filtered(x, c_ref, h, order)[m] for x, h, m in used]
    scale = sum(float(np.sum(r ** 2)) for r in refs) / n
    risk, noisy = [], []
    for w in windows:
        c = savgol_coeffs(w, polyorder, deriv=order)
        width = max(w, ref[0])
        apart = float(np.sum((_centred(c, width) - _centred(c_ref, width)) ** 2))
        gain = float(np.sum(c ** 2))
        sq = sum(np.sum((_filtered(x, c, h, order)[m] - r) ** 2, axis=0)
                 for (x, h, m), r in zip(used, refs, strict=True)) / n
        risk.append(float(np.sum(sq - s ** 2 * (apart - gain) * inv)))
        noisy.append(float(np.sum(s ** 2) * gain * inv))
    return np.array(risk), np.array(noisy), scale


def choose(pieces, polyorder: int, order: int, high: int, target: str = "") -> Choice:
    """The window for the `order`-th derivative of the pieces' signals (see the module doc). `pieces`: (x (T, d),
    h, real (T,) bool), those of the file's trajectories long enough for the smallest window."""
    s = noise(pieces)
    windows = candidates(polyorder, high)
    longest = max(len(x) for x, _, _ in pieces)
    windows = [w for w in windows if w < longest] or windows[:1]
    margin = min(max(windows[-1], smallest(polyorder + 2)), longest - 1) // 2
    ref, seen = (windows[0], polyorder), []
    for _ in range(ROUNDS):
        risk, noisy, scale = _risks(pieces, s, windows, ref, polyorder, order, margin)
        i = int(np.flatnonzero(risk <= risk.min() + TIE * scale)[0])
        if windows[i] in seen:
            break
        seen.append(windows[i])
        ref = (max(windows[i], smallest(polyorder + 2)), polyorder + 2)
        if ref[0] >= longest:
            break
    bias = max(float(risk[i] - noisy[i]), 0.0)
    return Choice(windows[i], polyorder, target, tuple(float(x) for x in s), float(np.sqrt(noisy[i])),
                  float(np.sqrt(bias)), windows[0], windows[-1])


def describe(record: dict) -> str:
    """A fit's derivative record (eval_config["derivatives"]) in words."""
    head = f"window {record.get('window')}, degree {record.get('polyorder')}"
    if record.get("rule") != AUTO or record.get("window") == AUTO:
        return head + (" (chosen per file from its noise)" if record.get("window") == AUTO else "")
    e = record.get("error_rms") or {}
    lo, hi = record.get("windows") or ("?", "?")
    noise_text = ", ".join(f"{s:.3g}" for s in record.get("noise") or [])
    return (f"{head}, chosen by --window auto for {record.get('target')}: the recording's noise estimated at "
            f"{noise_text} (standard deviation per coordinate), and of the odd windows {lo} to {hi} this one has the "
            f"least predicted error, rms {e.get('noise', float('nan')):.3g} from noise and "
            f"{e.get('bias', float('nan')):.3g} from the filter's bias")
