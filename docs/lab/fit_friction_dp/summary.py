"""Summarise the friction double-pendulum fits of run.sh: one row per model, the median and range over
seeds of each test-file number (the held-out trajectories of the training file beside, for choices).

    python docs/lab/fit_friction_dp/summary.py RESULTS_FOLDER
"""
import glob
import json
import sys
from collections import defaultdict
from statistics import median

ROWS = [("one-step L1 / null", "l1_ratio"), ("rollout error (geometric mean)", "rollout_gmean_err"),
        ("valid prediction time (s)", "vpt_s"), ("true energy error at the end", "energy_err_final"),
        ("friction, angle 1 (true {b})", "dissipation_coefficient_0"),
        ("friction, angle 2 (true {b})", "dissipation_coefficient_1"), ("training time (s)", "train_time_s")]


def fits(folder: str):
    """(model label, seed folder name, result record) of every fit under `folder`, in path order."""
    for f in sorted(glob.glob(f"{folder}/**/units/fit/*/*/seed*/result.json", recursive=True)):
        if "/starved/" in f:   # a deliberately starved control, reported by its own console line
            continue
        parts = f.split("/")
        yield parts[-3], parts[-2], json.load(open(f))


def numbers(folder: str, split: str) -> dict:
    """{model label: {key: [value per seed]}} of every fit under `folder`."""
    out: dict = defaultdict(lambda: defaultdict(list))
    for model, _, r in fits(folder):
        m = r["metrics"]
        row = out[model]
        row["l1_ratio"].append(m[f"{split}_l1"] / m[f"null_{split}_l1"])
        for key in ("rollout_gmean_err", "vpt_s", "energy_err_final", "dissipation_coefficient_0",
                    "dissipation_coefficient_1"):
            row[key].append(m.get(f"{split}_{key}"))
        row["train_time_s"].append(r.get("train_time_s"))
    return out


def fmt(x) -> str:
    return f"{x:.3g}"


def cell(values) -> str:
    v = [x for x in values if x is not None]
    if not v:
        return "–"
    return fmt(median(v)) + (f" ({fmt(min(v))}–{fmt(max(v))})" if len(v) > 1 else "") + f" [{len(v)}]"


if __name__ == "__main__":
    folder, b = sys.argv[1], (sys.argv[2] if len(sys.argv) > 2 else "b")
    for split in ("test", "heldout"):
        data = numbers(folder, split)
        models = sorted(data)
        print(f"\n{split}: median (range) [seeds]\n")
        print("| | " + " | ".join(models) + " |")
        print("|---" * (len(models) + 1) + "|")
        for label, key in ROWS:
            print(f"| {label.format(b=b)} | " + " | ".join(cell(data[m][key]) for m in models) + " |")
