"""Checks of one value, written once for the whole suite (the ground floor: imports nothing of it).

Two kinds of function:
- predicates, value -> bool: `is_integer(v)` (an int or a NumPy integer: never a bool, never a float, not even
  8.0, so that a count is never silently a float) and `is_real(v)` (a finite int or float, NumPy's too, never a
  bool: a real field accepts an integer).
- checks, (name, value, ...) -> the value, raising ValueError with a message that names the field, what it
  accepts and what it got: "<name> must be <what>, got <value!r>", or for a choice "unknown <name> <value!r>;
  valid: a, b". `integer` returns `int(v)` (a NumPy integer becomes a Python int); `real`, `positive` and
  `one_of` return the value as given (a record that stores floats converts it: JSON writes 2 and 2.0
  differently, so a key built from the value keeps what the caller gave); `integers` returns a tuple.

`check(ok, message)` raises ValueError(message) unless ok: the form of a check of several fields at once.
"""
from __future__ import annotations

import math
import numbers


def check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def is_integer(v) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def is_real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)


def _bounds(low, high) -> str:
    if low is not None and high is not None:
        return f" from {low} to {high}"
    return f" >= {low}" if low is not None else f" <= {high}" if high is not None else ""


def integer(name: str, v, low: int | None = None, high: int | None = None) -> int:
    """An integer in [low, high] (a bound left None is open)."""
    check(is_integer(v) and (low is None or v >= low) and (high is None or v <= high),
          f"{name} must be an integer{_bounds(low, high)}, got {v!r}")
    return int(v)


def integers(name: str, v, low: int | None = None) -> tuple:
    """A non-empty sequence (list or tuple) of integers >= low, as a tuple of ints."""
    check(isinstance(v, list | tuple) and len(v) > 0 and all(is_integer(x) and (low is None or x >= low) for x in v),
          f"{name} must be a non-empty sequence of integers{_bounds(low, None)}, got {v!r}")
    return tuple(int(x) for x in v)


def real(name: str, v, low: float | None = None, below: float | None = None):
    """A finite number, >= low and < below where given."""
    what = ("a finite number" + (f" >= {low}" if low is not None and below is None else "")
            + (f" in [{low}, {below})" if low is not None and below is not None else "")
            + (f" < {below}" if below is not None and low is None else ""))
    check(is_real(v) and (low is None or v >= low) and (below is None or v < below), f"{name} must be {what}, got {v!r}")
    return v


def positive(name: str, v):
    """A finite number > 0."""
    check(is_real(v) and v > 0, f"{name} must be positive and finite, got {v!r}")
    return v


def flag(name: str, v) -> bool:
    check(isinstance(v, bool), f"{name} must be True or False, got {v!r}")
    return v


def one_of(name: str, v, valid):
    check(v in valid, f"unknown {name} {v!r}; valid: {', '.join(map(str, valid))}")
    return v
