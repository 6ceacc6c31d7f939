"""Code generation: SymPy expressions -> one Python source -> NumPy / JAX / PyTorch callables.

``generate(fname, out, inputs, params)`` returns source text defining
``fname(q, qdot, qddot, tau, params, _z)`` where ``q``, ``qdot``, ``qddot``, ``tau`` are arrays
of shape (..., dof) (unused ones may be None), ``params`` a sequence of scalars or arrays
broadcastable to the batch shape (...), and ``_z`` a zero array of the batch shape (...)
that every output entry is added to (so constants broadcast and keep the dtype).
``out`` is one of:

- ``("scalar", expr)``            -> (...,)
- ``("vector", [e_0 .. e_n-1])``  -> (..., n)
- ``("matrix", Matrix n x n)``    -> (..., n, n)
- ``("solve", (Matrix, [b..]))``  -> (..., n): batched linear solve of M x = b

Common subexpressions are eliminated with ``sympy.cse``. The same source serves every backend:
``compile_source(src, fname, backend)`` executes it in the namespace of ``systems.backends``.
"""

from __future__ import annotations

import linecache

import sympy as sp
from sympy.printing.str import StrPrinter

from lagbench.systems import backends

CODEGEN_VERSION = "1"

_ARGS = (("q", "_q"), ("qdot", "_v"), ("qddot", "_a"), ("tau", "_t"))


class _Printer(StrPrinter):
    """StrPrinter whose output is valid Python for every backend namespace."""

    def __init__(self):
        super().__init__({"order": "none", "full_prec": True})

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"


def _flatten(kind: str, body) -> list:
    if kind == "scalar":
        return [body]
    if kind == "vector":
        return list(body)
    if kind == "matrix":
        return list(body)
    if kind == "solve":
        m, b = body
        return list(m) + list(b)
    raise ValueError(f"unknown output kind {kind!r}")


def generate(fname: str, out: tuple, inputs: dict, params: tuple) -> str:
    """Source text of ``fname``; ``inputs`` maps "q"/"qdot"/"qddot"/"tau" to tuples of symbols."""
    kind, body = out
    flat = [sp.sympify(e) for e in _flatten(kind, body)]
    rename, lines = {}, []
    used = set().union(*(e.free_symbols for e in flat)) if flat else set()
    for arg, prefix in _ARGS:
        for i, sym in enumerate(inputs.get(arg, ())):
            new = sp.Symbol(f"{prefix}{i}", real=True)
            rename[sym] = new
            if sym in used:
                lines.append(f"    {new} = {arg}[..., {i}]")
    for i, sym in enumerate(params):
        new = sp.Symbol(f"_p{i}", real=True)
        rename[sym] = new
        if sym in used:
            lines.append(f"    {new} = params[{i}]")
    unknown = used - set(rename)
    if unknown:
        raise ValueError(f"{fname}: expressions use undeclared symbols {sorted(map(str, unknown))}")
    flat = [e.xreplace(rename) for e in flat]
    replacements, reduced = sp.cse(flat, symbols=sp.numbered_symbols("_x"), order="none")
    pr = _Printer()
    for sym, expr in replacements:
        lines.append(f"    {sym} = {pr.doprint(expr)}")
    terms = [f"({pr.doprint(e)}) + _z" for e in reduced]
    lines.append(f"    return {_assemble(kind, body, terms)}")
    header = f"def {fname}(q, qdot, qddot, tau, params, _z):"
    return "\n".join([header, *lines]) + "\n"


def _stack(items: list) -> str:
    return "_stack([" + ", ".join(items) + "], -1)"


def _assemble(kind: str, body, terms: list) -> str:
    if kind == "scalar":
        return terms[0]
    if kind == "vector":
        return _stack(terms)
    if kind == "matrix":
        n = body.shape[1]
        rows = [_stack(terms[i : i + n]) for i in range(0, len(terms), n)]
        return "_stack([" + ", ".join(rows) + "], -2)"
    m = body[0]
    n = m.shape[1]
    k = m.shape[0] * n
    rows = [_stack(terms[i : i + n]) for i in range(0, k, n)]
    return "_solve(_stack([" + ", ".join(rows) + "], -2), " + _stack(terms[k:]) + ")"


def compile_source(src: str, fname: str, backend: str, label: str = ""):
    """Execute ``src`` in ``backend``'s namespace and return the function ``fname``."""
    filename = f"<lagbench-generated {label or fname} [{backend}]>"
    linecache.cache[filename] = (len(src), None, src.splitlines(True), filename)
    ns = dict(backends.namespace(backend))
    exec(compile(src, filename, "exec"), ns)  # noqa: S102 - our own generated source
    return ns[fname]
