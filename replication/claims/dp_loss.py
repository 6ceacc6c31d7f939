"""Claim 1 (LNN §5): the LNN and the baseline reach similar held-out loss on the double pendulum."""
from replication.claims import double_pendulum as dp
from replication.claims.base import Claim


def _similar(v):
    a, b = v.get("lnn"), v.get("baseline")
    if a is None or b is None:
        return "not run", "missing a model"
    r = a / b
    if 1 / 3 <= r <= 3:
        return "reproduced", f"lnn/baseline held-out L1 ratio {r:.2f} within [1/3, 3]"
    if 0.1 <= r <= 10:
        return "partly", f"lnn/baseline ratio {r:.2f} within 10x but not 3x"
    return "not reproduced", f"lnn/baseline ratio {r:.2f}"


CLAIM = Claim(
    id="dp_loss", number=1, paper="LNN", section="§5, double pendulum",
    title="LNN and baseline reach similar held-out loss on the double pendulum",
    system="double_pendulum", models=dp.MODELS, protocols=dp.PROTOCOLS, evaluate="heldout",
    metric="heldout_l1", metric_label="held-out per-sample L1 of q-double-dot (sum over 2 components)",
    published={"lnn": 7.3e-2, "baseline": 7.4e-2},
    verdict_rule="lnn / baseline within [1/3, 3] (partly: within 10x)", verdict=_similar,
    seeds=dp.SEEDS,
)
