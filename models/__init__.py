"""Models, framework-neutral part: the spec, the parameter layout and the initialisation.

    from models import ModelSpec, init_params
    spec = ModelSpec(kind="lnn", dof=2, hidden=(600, 600, 600))
    params = init_params(spec, seed=0)          # dict[str, np.ndarray], layout in models.params
    import models.jax, models.torch
    mj, mt = models.jax.build(spec, params), models.torch.build(spec, params)
"""
import os as _os

_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # busy-waiting OpenMP threads stall a loaded CPU (CONTRIBUTING)

from models.activations import ACTIVATIONS
from models.init import init_params
from models.params import check_params, layer_table, param_shapes
from models.spec import DTYPES, FORMULATIONS, INITS, KINDS, ModelSpec

__all__ = ["ACTIVATIONS", "DTYPES", "FORMULATIONS", "INITS", "KINDS", "ModelSpec", "check_params",
           "init_params", "layer_table", "param_shapes"]
