"""What the derivative filter alone does to a recording's acceleration targets: a noisy recording and the same
recording simulated without camera noise (same simulate seed, so the same trajectories and dropped frames),
read at fixed windows (degree 3, gaps split). For each window: the rows' q-double-dot error against the exact
dynamics at the rows' states for the noise-free file (the filter's bias: its rms, median and tails) and the
camera noise's share (noisy minus noise-free targets); the friction that the exact conservative part reads
(`identification.oracle`: L1, least squares) from noise-free targets, from noisy ones, and from each mixed with
the other's states. No model is trained.

    lagbench simulate ... --noise 0.0087 --seed 30 --out noisy.csv
    lagbench simulate ... --noise 0 --seed 30 --out clean.csv
    python docs/lab/recording_defaults/filter_bias_tails.py noisy.csv clean.csv [WINDOW ...]   (default 7 11 15)
"""
import sys
from pathlib import Path

import numpy as np

from lagbench import systems
from lagbench.files import user_data
from lagbench.replication.fit import trajectories

sys.path.insert(0, str(Path(__file__).parent))
from identification import oracle  # noqa: E402


def main(noisy: str, clean: str, windows: list[int]) -> None:
    exact = systems.registry.get("double_pendulum", friction=0.2)
    exact_conservative = systems.registry.get("double_pendulum", friction=0.0)
    paths = {"noisy": noisy, "clean": clean}
    files = {name: user_data.read(path)[1] for name, path in paths.items()}
    for w in windows:
        r = {name: trajectories.with_derivatives(d, paths[name], w, 3, gaps="split") for name, d in files.items()}
        if not np.array_equal(r["noisy"]["t"], r["clean"]["t"]):
            raise SystemExit("the two files do not hold the same rows: simulate both with the same seed")
        c = {k: np.asarray(r["clean"][k], np.float64) for k in ("q", "qdot", "qddot")}
        bias = c["qddot"] - np.asarray(exact.acceleration(c["q"], c["qdot"]))
        worst = np.abs(bias).max(1)
        noise = np.asarray(r["noisy"]["qddot"]) - c["qddot"]
        print(f"window {w}: {len(worst)} rows; q-double-dot rms {np.sqrt((c['qddot'] ** 2).mean()):.3g}; the filter's "
              f"bias rms {np.sqrt((bias ** 2).mean()):.3g}, median |bias| {np.median(np.abs(bias)):.3g}, 99th "
              f"percentile of a row's worst {np.quantile(worst, 0.99):.3g}, largest {worst.max():.3g}; camera noise "
              f"sd {noise.std(0).round(3)}", flush=True)
        mixes = {"noise-free": r["clean"], "noisy": r["noisy"],
                 "noise-free states, noisy targets": {**r["clean"], "qddot": r["noisy"]["qddot"]},
                 "noisy states, noise-free targets": {**r["noisy"], "qddot": r["clean"]["qddot"]}}
        for name, rows in mixes.items():
            l1, ls, _ = oracle(exact_conservative, rows)
            print(f"  friction read from {name}: L1 {l1.round(3)}, least squares {ls.round(3)}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], [int(a) for a in sys.argv[3:]] or [7, 11, 15])
