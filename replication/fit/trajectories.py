"""Trajectory input for `lagbench fit` / `evaluate`: derivatives estimated from sampled positions.

A trajectory file (see `lagbench.files.user_data`) holds rows of (traj, t, q[, qdot][, qddot][, tau]): one
or more trajectories, each sampled on its own uniform time grid. `with_derivatives(d, window,
polyorder)` returns the rows as state samples (q, qdot, qddot[, tau], traj, t), each trajectory sorted
by time. What the file gives is used as is; what it lacks is estimated, trajectory by trajectory:

  qdot   the first derivative of q;
  qddot  the first derivative of the given qdot, or else the second derivative of q.

The estimator is a Savitzky-Golay filter (`scipy.signal.savgol_filter`): at each sample, a polynomial of
degree `polyorder` is fitted by least squares to the `window` samples centred on it and differentiated
analytically there. The first and last window // 2 samples of a trajectory have no centred window (a
one-sided fit there is biased and several times noisier), so when any derivative is estimated they are
dropped: each trajectory keeps its samples window // 2 ... T - 1 - window // 2. Exact for polynomials of
degree <= polyorder; with white noise of standard deviation s on q at spacing h, the noise in the k-th derivative
scales as s / h^k / window^(k + 1/2): a wider window averages more noise away, but biases the estimate
where q curves on the window's time scale (window * h well below the motion's shortest period).
Checked against analytic trajectories with noise in tests/replication/fit/test_fit_trajectories.py.
`window` `AUTO` ("auto", `lagbench fit`'s default) reads the window off the recording: its noise and the
motion's own curvature give the window of least predicted error for the derivative the loss trains on, one
for the whole file (`choose_window`; the rule and its bounds: `replication.fit.derivative_window`).
`derivative_record` is what a fit records of it, `rule_of` reads a record back as a `--window`;
`position_noise` the noise it estimates on q, which a noisy recording's fit budget follows
(`replication.fit.kind_defaults.NOISY_RECORDINGS`).

Requirements (a ValueError naming the problem otherwise): "auto" or an odd window >= polyorder + 2 >= 3 (so
that the second derivative exists and the fit is overdetermined), at least window + 1 samples per
trajectory (two are left after the ends are dropped), strictly increasing times within a trajectory (a
file without a traj column is one trajectory, its rows in time order: times that repeat or go back there
are refused, naming the traj column that several trajectories need), and
samples on a uniform grid: the step h is the median step, a step within `JITTER_RTOL` (0.1 %) of h is h (real
clocks, times rounded when written), and a step within that of n x h (n >= 2) is a gap of n - 1 dropped
frames. Gaps (`gaps`, `GAPS`):
  interpolate  (default) fill gaps of at most `MAX_GAP` frames: each recorded array (q, and qdot, qddot,
               tau where given) by a cubic spline through the trajectory's samples, at the missing grid
               times; the filled rows serve the derivative windows of their neighbours and are then
               dropped (their values are made up); a longer gap is refused.
  split        the trajectory is cut at each gap into pieces, each its own trajectory (piece s of
               trajectory k gets the id k + s / 1000); pieces too short for a derivative window are dropped.
  refuse       a gap is an error.
Any other spacing is refused: resample such a recording onto a uniform grid first.
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.fit import derivative_window
from lagbench.replication.fit.derivative_window import AUTO, Choice
from lagbench.validate import is_integer

WINDOW = 15
POLYORDER = 3
JITTER_RTOL = 1e-3   # a step within this fraction of the median step is that step
MAX_GAP = 3          # the most dropped frames in a row that "interpolate" fills
GAPS = ("interpolate", "split", "refuse")


def check_options(window, polyorder) -> None:
    fixed = window != AUTO
    if not ((is_integer(window) or not fixed) and is_integer(polyorder)) or polyorder < 2 or \
            (fixed and (window % 2 == 0 or window < polyorder + 2)):
        raise ValueError(f"--window {window!r} / --polyorder {polyorder!r}: not valid; expected {AUTO} or an odd window "
                         f">= polyorder + 2, and a polyorder >= 2 (defaults {AUTO} and {POLYORDER})")


def _check_gaps(gaps) -> None:
    if gaps not in GAPS:
        raise ValueError(f"--gaps: {gaps!r} is not valid; expected one of {', '.join(GAPS)}")


def window_value(text: str):
    """--window's text: `AUTO` or an integer (checked by `check_options`)."""
    if text == AUTO:
        return AUTO
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"--window takes {AUTO} or an odd number of samples such as 31; got {text!r}") from None


def derivative(x, h: float, order: int, window: int = WINDOW, polyorder: int = POLYORDER):
    """The `order`-th time derivative of samples x (T, d) at uniform spacing h, by Savitzky-Golay."""
    from scipy.signal import savgol_filter

    return savgol_filter(np.asarray(x, np.float64), window, polyorder, deriv=order, delta=h, axis=0,
                         mode="interp")


def grid(t, where: str, gaps: str = "refuse") -> tuple[float, np.ndarray]:
    """(h, frame): the step of the times t (T,) and each sample's frame on the grid t[0] + frame x h; a
    ValueError naming `where` if they are not on one (see the module doc), or hold a gap `gaps` refuses. A lone
    sample has no step (h NaN)."""
    if len(t) < 2:   # no step to take a median of (NumPy would warn on the empty slice)
        return float("nan"), np.zeros(len(t), dtype=int)
    dt = np.diff(t)
    if not np.all(dt > 0):
        raise ValueError(f"{where}: times are not strictly increasing")
    h = float(np.median(dt))
    n = np.rint(dt / h)
    off = np.abs(dt - n * h) > JITTER_RTOL * h
    if np.any(off):
        i = int(np.argmax(off))
        raise ValueError(f"{where}: times are not uniformly spaced (a step of {dt[i]:.6g} at t = {t[i]:.6g} against "
                         f"the median step {h:.6g}; steps within {JITTER_RTOL:g} of it, or of a whole multiple of it "
                         f"(dropped frames), are accepted); resample the trajectory onto a uniform grid first")
    if np.any(n > 1):
        i = int(np.argmax(n))
        missing = int(n[i]) - 1
        if gaps == "refuse" or (gaps == "interpolate" and missing > MAX_GAP):
            hint = f"--gaps split ({MAX_GAP} at most are interpolated)" if gaps == "interpolate" else \
                "--gaps interpolate or split"
            raise ValueError(f"{where}: {missing} dropped frame(s) after t = {t[i]:.6g}; {hint}")
    if np.all(n == 1):   # no gap: the mean step (the same derivatives as for an exactly uniform grid)
        h = float(np.mean(dt))
    return h, np.concatenate([[0], np.cumsum(n)]).astype(int)


def _filled(part: dict, frame: np.ndarray, h: float) -> dict:
    """`part` on the whole grid: the dropped frames' arrays by cubic splines through the samples, `filled` marks
    them."""
    from scipy.interpolate import CubicSpline

    full = np.arange(frame[-1] + 1)
    t = part["t"][0] + full * h
    t[frame] = part["t"]
    missing = np.setdiff1d(full, frame)
    out = {"t": t, "filled": np.isin(full, missing)}
    for key, v in part.items():
        if key == "t":
            continue
        if key == "traj":
            out[key] = np.full(full.size, v[0])
            continue
        w = np.empty((full.size, *v.shape[1:]))
        w[frame] = v
        w[missing] = CubicSpline(part["t"], v, axis=0)(t[missing])
        out[key] = w
    return out


def _pieces(part: dict, frame: np.ndarray, h: float, gaps: str) -> list[dict]:
    """The trajectory as the pieces `gaps` makes of it: itself (no gap), filled, or cut at its gaps."""
    if frame[-1] == frame.size - 1:
        return [part]
    if gaps == "interpolate":
        return [_filled(part, frame, h)]
    cuts = np.flatnonzero(np.diff(frame) > 1) + 1
    bounds = zip(np.concatenate([[0], cuts]), np.concatenate([cuts, [frame.size]]), strict=True)
    return [{k: (v[a:b] + s / 1000 if k == "traj" else v[a:b]) for k, v in part.items()}
            for s, (a, b) in enumerate(bounds)]


def _trajectories(d: dict, path: str, gaps: str) -> list[tuple[str, float, list[dict]]]:
    """(where, h, pieces) of each trajectory of the arrays `d`, its rows sorted by time (see the module doc)."""
    if "traj" not in d:
        _one_trajectory(d["t"], path)
    traj = d.get("traj", np.zeros(len(d["q"])))
    out = []
    for k in np.unique(traj):
        rows = np.flatnonzero(traj == k)
        rows = rows[np.argsort(d["t"][rows], kind="stable")]
        where = f"{path}: trajectory {k:g}"
        h, frame = grid(d["t"][rows], where, gaps)
        whole = {"traj": np.full(rows.size, float(k)), **{key: d[key][rows] for key in ("t", "q", "qdot", "qddot", "tau")
                                                          if key in d}}
        out.append((where, h, _pieces(whole, frame, h, gaps)))
    return out


def _estimated(d: dict) -> tuple[int, str] | None:
    """(order, signal) of the derivative the loss trains on where the file lacks it: q̈ from q, q̈ from the given
    q̇, or q̇ from q (the file gives q̈); None where the file gives both."""
    if "qddot" not in d:
        return (1, "qdot") if "qdot" in d else (2, "q")
    return None if "qdot" in d else (1, "q")


def choose_window(d: dict, path: str, polyorder: int = POLYORDER, gaps: str = "interpolate") -> Choice | None:
    """The window `--window auto` takes for a trajectory file's arrays `d` (times in seconds), one for the whole
    file (`derivative_window.choose` over its trajectories' pieces, at most `MAX_SHARE` of its shortest
    trajectory); None where the file gives both derivatives (nothing is estimated)."""
    check_options(AUTO, polyorder)
    _check_gaps(gaps)
    what = _estimated(d)
    if what is None:
        return None
    order, signal = what
    pieces, high = _signal_pieces(d, path, signal, polyorder, gaps)
    return derivative_window.choose(pieces, polyorder, order, high, derivative_window.TARGETS[what])


def _signal_pieces(d: dict, path: str, signal: str, polyorder: int, gaps: str) -> tuple[list, int]:
    """([(x, h, real)] of the file's trajectory pieces long enough for the smallest window, `signal` their x;
    the longest window the file allows): what `derivative_window` reads."""
    found = _trajectories(d, path, gaps)
    high = derivative_window.highest(min(sum(p["t"].size for p in pieces) for _, _, pieces in found), polyorder)
    low = derivative_window.smallest(polyorder)
    pieces = [(p[signal], h, ~p.get("filled", np.zeros(p["t"].size, bool))) for _, h, ps in found for p in ps
              if p["t"].size >= low + 1]
    if not pieces:
        where, _, ps = found[0]
        raise ValueError(f"{where} has {max(p['t'].size for p in ps)} samples; estimating its derivatives needs at "
                         f"least {low + 1}")
    return pieces, high


def position_noise(d: dict, path: str, polyorder: int = POLYORDER, gaps: str = "interpolate") -> float | None:
    """The noise on the positions of a trajectory file's arrays `d` where its q-double-dot is estimated from q
    (the file gives neither derivative): the mean over coordinates of what `--window auto` estimates
    (`derivative_window.noise`, the record's "noise"), in q's units; None where the file gives a derivative."""
    _check_gaps(gaps)
    if _estimated(d) != (2, "q"):
        return None
    return float(np.mean(derivative_window.noise(_signal_pieces(d, path, "q", polyorder, gaps)[0])))


def derivative_record(d: dict, path: str, window, polyorder: int = POLYORDER, gaps: str = "interpolate") -> dict:
    """What a fit records of the derivatives of the arrays `d` (times in seconds) and estimates them with:
    {"window", "polyorder"}, the window an integer given or, for `AUTO`, the one chosen with its reasons
    (`derivative_window.Choice.record`); "auto" where nothing is estimated (a state file, or both given)."""
    choice = choose_window(d, path, polyorder, gaps) if window == AUTO and "t" in d else None
    return choice.record() if choice is not None else {"window": window, "polyorder": polyorder}


def rule_of(record: dict):
    """The `--window` a fit's derivative record (eval_config["derivatives"]) stands for: `AUTO` where the fit chose
    it from its data, else the window it used (`WINDOW` where it recorded none)."""
    return AUTO if AUTO in (record.get("rule"), record.get("window")) else record.get("window", WINDOW)


def with_derivatives(d: dict, path: str, window: int | str = WINDOW, polyorder: int = POLYORDER,
                     gaps: str = "interpolate") -> dict:
    """State samples (q, qdot, qddot[, tau], traj, t) from a trajectory file's arrays `d` (see module doc);
    `window` `AUTO`: the one `choose_window` takes."""
    check_options(window, polyorder)
    _check_gaps(gaps)
    estimate = "qdot" not in d or "qddot" not in d
    if window == AUTO:
        window = choose_window(d, path, polyorder, gaps).window if estimate else WINDOW
    parts = []
    for where, h, pieces in _trajectories(d, path, gaps):
        long_enough = [p for p in pieces if not estimate or p["t"].size >= window + 1]
        if not long_enough:
            n = max(p["t"].size for p in pieces)
            raise ValueError(f"{where} has {n} sample{'s' if n != 1 else ''}"
                             f"{' in its longest piece between gaps' if len(pieces) > 1 else ''}; "
                             f"estimating its derivatives needs at least {window + 1} (--window {window}, whose first "
                             f"and last {window // 2} are dropped)")
        parts += [_derivatives(p, h, window, polyorder, estimate) for p in long_enough]
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _one_trajectory(t, path: str) -> None:
    """A file without a traj column is one trajectory, its rows in time order: times that repeat or go back
    are what several trajectories one after another look like (a ValueError naming the traj column)."""
    dt = np.diff(t)
    back = np.flatnonzero(~(dt > 0))
    if back.size:
        i = int(back[0])
        how = "repeat" if dt[i] == 0 else "go back"
        raise ValueError(f"{path}: its times {how} (t = {t[i]:.6g} then {t[i + 1]:.6g}, data rows {i + 1} and "
                         f"{i + 2}) and it has no traj column, so it is read as one trajectory; several trajectories "
                         f"need a traj column naming each row's trajectory")


def _derivatives(part: dict, h: float, window: int, polyorder: int, estimate: bool) -> dict:
    """One piece of a trajectory with what it lacks estimated, the ends and any filled rows dropped."""
    part = dict(part)
    filled = part.pop("filled", None)
    if "qddot" not in part:   # of the given qdot, else the second derivative of q
        given = "qdot" in part
        part["qddot"] = derivative(part["qdot"] if given else part["q"], h, 1 if given else 2, window, polyorder)
    if "qdot" not in part:
        part["qdot"] = derivative(part["q"], h, 1, window, polyorder)
    keep = np.ones(part["t"].size, bool)
    if estimate:  # no centred window at the ends
        keep[: window // 2], keep[part["t"].size - window // 2:] = False, False
    if filled is not None:
        keep &= ~filled
    return {key: part[key][keep] for key in ("traj", "t", "q", "qdot", "qddot", "tau") if key in part}


def starts(traj) -> list[np.ndarray]:
    """The row indices of each trajectory of `traj` (N,), in order of first appearance."""
    traj = np.asarray(traj)
    _, first = np.unique(traj, return_index=True)
    return [np.flatnonzero(traj == traj[i]) for i in np.sort(first)]
