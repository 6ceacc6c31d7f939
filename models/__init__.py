"""Models, framework-neutral part: the spec, the parameter layout and the initialisation.

    from lagbench.models import ModelSpec, init_params
    spec = ModelSpec(kind="lnn", dof=2, hidden=(600, 600, 600))
    params = init_params(spec, seed=0)          # dict[str, np.ndarray], layout in lagbench.models.params
    import lagbench.models.jax
    import lagbench.models.torch
    mj, mt = lagbench.models.jax.build(spec, params), lagbench.models.torch.build(spec, params)
"""
from lagbench.models.activations import ACTIVATIONS
from lagbench.models.init import init_params
from lagbench.models.params import check_params, layer_table, param_shapes
from lagbench.models.spec import DTYPES, FORMULATIONS, INITS, KINDS, ModelSpec

__all__ = ["ACTIVATIONS", "DTYPES", "FORMULATIONS", "INITS", "KINDS", "ModelSpec", "check_params",
           "init_params", "layer_table", "param_shapes"]
