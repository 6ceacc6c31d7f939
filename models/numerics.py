"""Numerical thresholds shared by both frameworks.

`rcond_min(dtype, d)`: the fast Euler-Lagrange solve falls back to the pseudo-inverse where the
velocity Hessian's reciprocal 1-norm condition number 1/(|H|_1 |H^-1|_1) is below this, or where
the solve is not finite. It equals the pseudo-inverse cutoff `pinv_rtol` (10 * d * eps), so above
it the fallback would give the same answer as the solve.
`pinv_rtol(dtype, d)`: relative singular-value cutoff of pinv, passed explicitly to both
frameworks (JAX's default; PyTorch's default is 10x smaller).
"""
import numpy as np

EPS = {"float32": float(np.finfo(np.float32).eps), "float64": float(np.finfo(np.float64).eps)}


def pinv_rtol(dtype: str, d: int) -> float:
    return 10.0 * d * EPS[dtype]


def rcond_min(dtype: str, d: int) -> float:
    return pinv_rtol(dtype, d)
