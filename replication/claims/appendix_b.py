"""Claim 5 (LNN Appendix B): the Euler-Lagrange step on the exact free-fall Lagrangian gives (-g, 0).

No training: the exact Lagrangian of `systems.get("free_fall")` is written as a model and passed
through each framework's Euler-Lagrange routine, in both formulations, in float64.
"""
from lagbench.replication.claims.base import Claim, ModelEntry, Part
from lagbench.replication.claims.published import Published
from lagbench.replication.claims.rules import bound
from lagbench.replication.training.protocol import Data, Protocol

MODELS = (ModelEntry("lnn_exact_paper", {"kind": "lnn", "formulation": "paper"}, train=False),
          ModelEntry("lnn_exact_fast", {"kind": "lnn", "formulation": "fast"}, train=False))
_p = Protocol(data=Data("free_fall_iid", n_train=1, n_heldout=256), steps=1, batch=1, dtype="float64")


CLAIM = Claim(
    id="appendix_b", number=5, paper="LNN", section="Appendix B",
    title="Euler-Lagrange on the exact free-fall Lagrangian gives qdd = (-g, 0)",
    system="free_fall", models=MODELS, protocols={"smoke": _p, "quick": _p, "full": _p, "paper": _p},
    evaluate="exact_lagrangian", metric="max_abs_err", metric_label="max |qdd - (-g, 0)| over random states",
    published={m.label: Published(0.0, "exact", "LNN Appendix B: qdd = (-g, 0) analytically",
                                  metric="max_abs_err") for m in MODELS},
    verdict_rule="max error <= 1e-12 (float64)", kind="check",
    parts=(Part("exact free fall", bound("max_abs_err", upper=1e-12), reads=tuple(m.label for m in MODELS)),),
    seeds={"smoke": 1, "quick": 1, "full": 1, "paper": 1},
)
