"""build(spec, params) -> the PyTorch model of spec.kind; to_params(model) -> the NumPy layout."""
from __future__ import annotations

from models.params import check_params
from models.spec import ModelSpec
from models.torch.baseline import Baseline
from models.torch.delan import DeLaN
from models.torch.hnn import HNN
from models.torch.lgn import LGN
from models.torch.lnn import LNN

CLASSES = {"baseline": Baseline, "lnn": LNN, "hnn": HNN, "delan": DeLaN, "lgn": LGN}


def build(spec: ModelSpec, params: dict):
    """An nn.Module of class CLASSES[spec.kind] whose parameters are params cast to spec.dtype."""
    check_params(spec, params)
    return CLASSES[spec.kind](spec, params)


def to_params(model) -> dict:
    """{key: np.ndarray} with the same keys and shapes as `init_params` gives."""
    return {k: v.detach().cpu().numpy().copy() for k, v in model.named_parameters()}
