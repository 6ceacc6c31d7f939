"""The friction bracket of a dissipative LNN fit, with its coefficients scaled: for each SCALES (comma-separated
factors, one per coordinate, e.g. 1,1 or 0.02,0.42), the fit's Rayleigh coefficients b are set to scale x its
own, and on its test file and its held-out trajectories the rollout error (S_rollout_gmean_err) is printed with
the ratios `replication.fit.dissipation` reads: the dissipation removed ("off"), every coefficient halved
("x0.5") and doubled ("x2.0"), each over the error at the scaled coefficients. A scaled model is the fit with
a friction it did not learn: the gate should read the fit's own and refuse a scale that is wrong.

    python docs/lab/friction_gate/bracket.py FIT_UNIT_FOLDER 1,1 0.5,0.5 2,2 ...
"""
import sys

import numpy as np

from lagbench.files import user_data
from lagbench.replication.fit.dissipation import BRACKET, bracket_ratios, softplus, with_coefficients
from lagbench.replication.fit.load import load_fitted
from lagbench.replication.fit.rollout_groups import mean_state_error


def main(folder: str, scales: list[str]) -> None:
    f = load_fitted(folder)
    cfg = f.result["eval_config"]
    sets = {"test": user_data.rows(cfg["test"], "test"), "heldout": user_data.rows(f.protocol.data.recipe, "heldout")}
    for scale in scales:
        b = softplus(f.params["dissipation.raw"]) * np.array([float(x) for x in scale.split(",")])
        for name, r in sets.items():
            base = mean_state_error(with_coefficients(f, b), r)
            row = {"err": base, "off": mean_state_error(with_coefficients(f, 0 * b), r) / base}
            row.update({f"x{k}": x for k, x in zip(BRACKET, bracket_ratios(f, r, b, base=base), strict=True)})
            print(scale, name, {k: round(v, 3) for k, v in row.items()}, flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
