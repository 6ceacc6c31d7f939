"""How `lagbench fit`'s flags are read and what a valid value is: the parsers and validators its option
records (`replication.fit.options`) name.

`count(low)`, `one_of(values)`: validators (value -> bool). `widths(text, option)`: layer widths from "128,128"
(also `lagbench train-target`'s). `scale(text)`: --input-scale. `periodic_value(text)` and `valid_periodic(v)`:
--periodic.
"""
from __future__ import annotations

from lagbench.replication.fit.trajectories import AUTO
from lagbench.validate import is_integer


def count(low):
    return lambda v: is_integer(v) and v >= low


def one_of(values):
    return lambda v: v in values


def widths(text: str, option: str = "--hidden") -> tuple:
    """Layer widths from "128,128"; a ValueError naming `option` otherwise (also `lagbench train-target`'s)."""
    try:
        out = tuple(int(x) for x in text.split(","))
    except ValueError:
        out = ()
    if not out or min(out) < 1:
        raise ValueError(f"{option} takes comma-separated layer widths >= 1 such as 128,128; got {text!r}")
    return out


def scale(text: str):
    """--input-scale: None (none), "auto" or a tuple of numbers."""
    if text in ("none", "auto"):
        return None if text == "none" else "auto"
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"--input-scale takes none, auto or comma-separated numbers such as 1,1,0.3,0.3; got "
                         f"{text!r}") from None


def periodic_value(text: str):
    """--periodic: "auto", () for none, or a tuple of indices (a non-digit left for `valid_periodic` to refuse)."""
    if text in (AUTO, "none"):
        return AUTO if text == AUTO else ()
    return tuple(int(x) if x.strip().isdigit() else x for x in text.split(","))


def valid_periodic(v) -> bool:
    return v == AUTO or (isinstance(v, tuple | list) and all(count(0)(k) for k in v))
