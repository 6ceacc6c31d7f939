"""The recording-defaults study's table (run.sh's folders OUT/s<seed>-<arm>): per arm, each seed's numbers on
the development test file: one-step L1 over the null's and over the exact dynamics' own on the same file (the
system with the file's friction, at the file's filtered states, against its estimated q-double-dot: the floor
the recording's noise sets), rollout error, valid prediction time, true energy error at the end, the friction
read (or why not), its rollout bracket and the training's wall seconds.

    python docs/lab/recording_defaults/summary.py OUT [FRICTION]
"""
import glob
import json
import re
import sys
from collections import defaultdict

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.evaluation.metrics import heldout_errors

_floor: dict = {}


def exact_l1(reference: str, friction: float) -> float:
    """The exact dynamics' one-step L1 on a prepared file (per-sample sum over components, mean over samples)."""
    if reference not in _floor:
        r = user_data.rows(reference, "test")
        pred = np.asarray(systems.registry.get("double_pendulum", friction=friction).acceleration(r["q"], r["qdot"]))
        _floor[reference] = heldout_errors(pred, r["qddot"])["l1"]
    return _floor[reference]


def row(r: dict, friction: float) -> dict:
    m, c = r["metrics"], r.get("counters") or {}
    friction_read = [m.get(f"test_dissipation_coefficient_{k}") for k in (0, 1)]
    return {"one-step / null": m["test_l1"] / m["null_test_l1"],
            "one-step / exact": m["test_l1"] / exact_l1(r["eval_config"]["test"], friction),
            "rollout error": m["test_rollout_gmean_err"], "valid time (s)": m["test_vpt_s"],
            "energy error at end": m.get("test_energy_err_final"),
            "friction": (", ".join(f"{x:.3g}" for x in friction_read) if friction_read[0] is not None else
                         c.get("test_dissipation_coefficient", "-")),
            "bracket": (f"{m['test_dissipation_bracket_half']:.3g} / {m['test_dissipation_bracket_double']:.3g}"
                        if "test_dissipation_bracket_half" in m else "-"),
            "training s (wall)": r.get("train_time_s")}


def done_means(arms: dict, friction: float, lnn: str = "lnn_1x", baseline: str = "baseline") -> None:
    """The issue's bars on the seeds both arms have: the LNN's one-step L1 / null (at most 0.3), its rollout
    error / the baseline's (at most 1.2; median over seeds), each friction within 10 % of the truth (where read)
    and each fit's training within 10 minutes."""
    seeds = sorted(set(arms.get(lnn, {})) & set(arms.get(baseline, {})))
    if not seeds:
        return
    one = [arms[lnn][s]["one-step / null"] for s in seeds]
    ratio = [arms[lnn][s]["rollout error"] / arms[baseline][s]["rollout error"] for s in seeds]
    off = []
    for s in seeds:
        read = arms[lnn][s]["friction"]
        try:
            off.append(max(abs(float(x) / friction - 1) for x in read.split(",")))
        except ValueError:   # not read: the reason instead of numbers
            off.append(None)
    times = [arms[a][s]["training s (wall)"] for a in (lnn, baseline) for s in seeds]
    print(f"\ndone-means, {lnn} against {baseline}, seeds {', '.join(map(str, seeds))}:")
    print(f"- one-step / null: {', '.join(f'{x:.3g}' for x in one)}; median {np.median(one):.3g} (bar 0.3)")
    print(f"- rollout error / baseline's: {', '.join(f'{x:.3g}' for x in ratio)}; median {np.median(ratio):.3g} (bar 1.2)")
    print("- friction, largest relative miss per seed: "
          + ", ".join("not read" if x is None else f"{x:.1%}" for x in off) + " (bar 10 %)")
    print(f"- training s (wall), every fit: {', '.join('-' if t is None else f'{t:.0f}' for t in times)} (bar 600)")


def main(out: str, friction: float = 0.2) -> None:
    arms: dict = defaultdict(dict)
    for f in sorted(glob.glob(f"{out}/s*-*/units/fit/*/*/seed*/result.json")):
        seed, arm = re.match(r"s(\d+)-(.+)", f[len(out):].strip("/").split("/")[0]).groups()
        arms[arm][int(seed)] = row(json.load(open(f)), friction)
    for arm, seeds in arms.items():
        keys = list(next(iter(seeds.values())))
        print(f"\n{arm} (seeds {', '.join(map(str, sorted(seeds)))})")
        print("| " + " | ".join(["seed", *keys]) + " |")
        print("|" + "---|" * (len(keys) + 1))
        for s in sorted(seeds):
            cells = [v if isinstance(v, str) else "-" if v is None else f"{v:.3g}" for v in seeds[s].values()]
            print("| " + " | ".join([str(s), *cells]) + " |")
        numeric = [k for k in keys if all(isinstance(seeds[s][k], float | int) for s in seeds)]
        print("median over seeds: " + ", ".join(f"{k} {np.median([seeds[s][k] for s in seeds]):.3g}" for k in numeric))
    done_means(arms, friction)


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]) if len(sys.argv) > 2 else 0.2)
