"""The one parameter layout both frameworks load: a flat dict[str, np.ndarray].

Keys (weights are (out, in), as torch.nn.Linear; biases (out,)):
  every kind:  "mlp.{i}.weight", "mlp.{i}.bias" for i = 0 .. len(spec.mlp_sizes()) - 2
               (the density MLP for lgn; the shared trunk on q for delan, every trunk layer activated)
  delan adds:  "delan_lower.weight" (dof*(dof-1)/2, hidden[-1]), "delan_lower.bias"  (absent if dof == 1)
               "delan_diag.weight"  (dof, hidden[-1]),            "delan_diag.bias"
               "delan_potential.weight" (1, hidden[-1]),          "delan_potential.bias"
  lnn, hnn, delan with spec.dissipation add "dissipation.raw" (dof,): the Rayleigh coefficients b = softplus(raw).
The order of `layer_table(spec)` is the order in which `models.init` draws them.
"""
from __future__ import annotations

import numpy as np

from lagbench.models.spec import USER_KIND, ModelSpec, capability


def layer_table(spec: ModelSpec) -> list:
    """[(prefix, fan_in, fan_out, role)], role "first" | "hidden" | "output"; drawing order."""
    sizes = spec.mlp_sizes()
    n = len(sizes) - 1
    rows = []
    for i in range(n):
        last = i == n - 1 and capability(spec.kind).mlp_head
        role = "output" if last else ("first" if i == 0 else "hidden")
        rows.append((f"mlp.{i}", sizes[i], sizes[i + 1], role))
    if spec.kind == "delan":
        h, d = spec.hidden[-1], spec.dof
        if d > 1:
            rows.append(("delan_lower", h, d * (d - 1) // 2, "output"))
        rows.append(("delan_diag", h, d, "output"))
        rows.append(("delan_potential", h, 1, "output"))
    return rows


def param_shapes(spec: ModelSpec) -> dict:
    """{key: shape} of the layout, in drawing order (a user's model: its module's parameters, `models.user`)."""
    if spec.kind == USER_KIND:
        from lagbench.models import user

        return user.param_shapes(spec)
    out = {}
    for prefix, fan_in, fan_out, _ in layer_table(spec):
        out[f"{prefix}.weight"] = (fan_out, fan_in)
        out[f"{prefix}.bias"] = (fan_out,)
    if spec.dissipation:
        out["dissipation.raw"] = (spec.dof,)
    return out


def check_params(spec: ModelSpec, params: dict) -> None:
    """Raise ValueError unless params has exactly the layout's keys and shapes."""
    shapes = param_shapes(spec)
    missing, unknown = set(shapes) - set(params), set(params) - set(shapes)
    if missing or unknown:
        raise ValueError(f"params do not match the {spec.kind!r} layout: missing {sorted(missing)}, "
                         f"unexpected {sorted(unknown)}")
    for k, shape in shapes.items():
        if tuple(np.shape(params[k])) != shape:
            raise ValueError(f"param {k!r}: expected shape {shape}, got {tuple(np.shape(params[k]))}")


def n_layers(spec: ModelSpec) -> int:
    """Number of Linear layers in the (trunk) MLP."""
    return len(spec.mlp_sizes()) - 1


def tril_selection(d: int) -> np.ndarray:
    """(d*d, d*(d+1)/2) 0/1 matrix S with L.reshape(d*d) = S @ concat([diag, strictly_lower]),
    strictly_lower in np.tril_indices(d, -1) order (row-major): how DeLaN assembles L."""
    s = np.zeros((d * d, d * (d + 1) // 2))
    for i in range(d):
        s[i * d + i, i] = 1.0
    for k, (i, j) in enumerate(zip(*np.tril_indices(d, -1), strict=True)):
        s[i * d + j, d + k] = 1.0
    return s
