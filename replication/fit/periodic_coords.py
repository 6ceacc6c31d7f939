"""`--periodic auto`: the coordinates in which a system's Lagrangian is 2 pi-periodic, found symbolically.

`periodic_in(name) -> tuple`: the indices k whose shift q_k -> q_k + 2 pi leaves the system's Lagrangian
(`systems.registry.definition(name)`, at its default options) unchanged, sympy.simplify(L(q + 2 pi e_k) - L(q))
== 0, and on which it depends at all: a coordinate absent from L (a free particle's horizontal position, the
four-joint arm's base rotation about the vertical) is invariant under every shift, so the Lagrangian cannot
tell an angle from a position there and it is left as it is. Computed once per system (in memory). The
pendulum, the double pendulum, the pendulum chain and the two-link arm come out periodic in every coordinate,
the four-joint arm in its three joints that gravity acts through, the spring, free fall, relativistic and
charged particles, the wave and the stiff chain in none.

`choose(periodic, system, angle_wrap) -> dict`: what a fit records (eval_config["periodic"]): {"mode",
"chosen" (the indices), "why"}; `auto` with a `--system` and without `--angle-wrap` takes `periodic_in`, and
otherwise none; a list of indices is used as given. `describe(record)` says it in words.
"""
from __future__ import annotations

import functools

AUTO = "auto"


@functools.cache
def periodic_in(name: str) -> tuple:
    import sympy as sp

    from lagbench.systems.registry import definition

    d = definition(name)
    lag = d.lagrangian
    return tuple(k for k, q in enumerate(d.q)
                 if q in lag.free_symbols and sp.simplify(lag.subs(q, q + 2 * sp.pi) - lag) == 0)


def _names(indices) -> str:
    return ", ".join(f"q{k}" for k in indices)


def choose(periodic, system, angle_wrap: bool) -> dict:
    if periodic != AUTO:
        chosen = [int(k) for k in periodic]
        return {"mode": ",".join(map(str, chosen)) or "none", "chosen": chosen, "why": "as given"}
    if angle_wrap:
        why = "--angle-wrap wraps the angles instead"
    elif system is None:
        why = "no --system to read the periodic coordinates from"
    else:
        chosen = list(periodic_in(system))
        why = (f"the Lagrangian of {system} is 2 pi-periodic in {'them' if len(chosen) > 1 else 'it'}" if chosen else
               f"the Lagrangian of {system} is 2 pi-periodic in none of its coordinates")
        return {"mode": AUTO, "chosen": chosen, "why": why}
    return {"mode": AUTO, "chosen": [], "why": why}


def describe(record: dict) -> str:
    """A fit's periodic-input record (eval_config["periodic"]) in words."""
    chosen = record.get("chosen") or []
    return f"{_names(chosen) if chosen else 'none'} (--periodic {record.get('mode')}: {record.get('why')})"
