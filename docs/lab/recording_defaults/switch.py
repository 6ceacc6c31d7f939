"""Item 5 of docs/lab/recording_defaults.md: where the LNN's budget on a recording switches from 3 x the claim's
steps to 1 x (without restart fallbacks), by the rule registered there. Per noise level: the position noise a
fit estimates on the level's training file (`trajectories.position_noise`, what the fit's switch reads), the
median over fit seeds of the development test file's rollout error at 1 x and at 3 x, and the winner (1 x
unless 3 x is more than `MARGIN` better); the switch is the geometric mean of the highest estimated noise
where 3 x won and the lowest where 1 x won.

    python docs/lab/recording_defaults/switch.py OUT_0.001 OUT_0.003 [--level NOISE:MEDIAN_1X:MEDIAN_3X ...]

OUT_*: run.sh folders with the arms lnn_1x and lnn_3x. `--level`: a level whose fits are recorded in the lab
note only (the first study's 0.0087 rad, whose folder is gone): its medians as written there, its training
file made again by run.sh's `simulate` command (seed 30) to estimate its noise.
"""
import argparse
import glob
import json
import re
import subprocess
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np

from lagbench.files import user_data
from lagbench.replication.fit import trajectories

MARGIN = 0.05   # 3 x wins only where its median rollout error is more than 5 % below 1 x's
SIMULATE = ("lagbench simulate --system double_pendulum --set friction=0.2 --rate 100 --dropped 0.02 "
            "--trajectories 400 --duration 1 --seed 30")


def estimated_noise(train_csv: str) -> float:
    return trajectories.position_noise(user_data.read(train_csv)[1], train_csv)


def medians(out: str) -> dict:
    rollouts = defaultdict(list)
    for f in glob.glob(f"{out}/s*-lnn_*x/units/fit/*/*/seed*/result.json"):
        arm = re.search(r"/s\d+-(lnn_\dx)/", f).group(1)
        rollouts[arm].append(json.load(open(f))["metrics"]["test_rollout_gmean_err"])
    if set(rollouts) != {"lnn_1x", "lnn_3x"} or len(rollouts["lnn_1x"]) != len(rollouts["lnn_3x"]):
        raise SystemExit(f"{out}: needs the arms lnn_1x and lnn_3x on the same seeds; has "
                         f"{ {k: len(v) for k, v in rollouts.items()} }")
    return {arm: float(np.median(v)) for arm, v in rollouts.items()} | {"seeds": len(rollouts["lnn_1x"])}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folders", nargs="*")
    p.add_argument("--level", action="append", default=[], help="NOISE:MEDIAN_1X:MEDIAN_3X")
    a = p.parse_args()
    rows = []
    for out in a.folders:
        rows.append({"level": out, "noise": estimated_noise(f"{out}/data/train.csv"), **medians(out)})
    for level in a.level:
        noise, m1, m3 = (float(x) for x in level.split(":"))
        with tempfile.TemporaryDirectory() as tmp:
            csv = str(Path(tmp) / "train.csv")
            subprocess.run([*SIMULATE.split(), "--noise", str(noise), "--out", csv], check=True, capture_output=True)
            rows.append({"level": f"{noise:g} rad (lab note)", "noise": estimated_noise(csv), "lnn_1x": m1,
                         "lnn_3x": m3, "seeds": "-"})
    print("| level | estimated position noise | fit seeds | median rollout 1 x | 3 x | 3 x better by | wins |")
    print("|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: r["noise"]):
        gain = 1 - r["lnn_3x"] / r["lnn_1x"]
        r["wins"] = "3 x" if gain > MARGIN else "1 x"
        print(f"| {r['level']} | {r['noise']:.4g} | {r['seeds']} | {r['lnn_1x']:.4g} | {r['lnn_3x']:.4g} | "
              f"{gain:.1%} | {r['wins']} |")
    three = [r["noise"] for r in rows if r["wins"] == "3 x"]
    one = [r["noise"] for r in rows if r["wins"] == "1 x"]
    if not three or not one:
        print("no switch: one budget wins at every level")
        return
    if max(three) >= min(one):
        print(f"no single switch: 3 x wins up to {max(three):.4g}, 1 x from {min(one):.4g}")
        return
    print(f"switch: {np.sqrt(max(three) * min(one)):.4g} (geometric mean of {max(three):.4g} and {min(one):.4g})")


if __name__ == "__main__":
    main()
