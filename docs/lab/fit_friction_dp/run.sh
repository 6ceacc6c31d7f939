#!/usr/bin/env bash
# The friction double pendulum of docs/fit.md: many short recordings (400 releases of 1 s at 100 Hz) with
# viscous friction FRICTION on both angles, noise 0.001 on q and 2 % of the frames dropped; a test file of 8
# recordings of 4 s. Each model fitted at claim 1's budget (the kind's defaults, with the LNNs' --steps given
# as the claim's: on a trajectory file their default is 3 x, docs/decisions/fit_budget.md) for SEEDS seeds,
# each fit into a folder of its own; then the summary table.
#   bash docs/lab/fit_friction_dp/run.sh OUT [FRICTION] [SEEDS]
set -euo pipefail
out=${1:?give a results folder}; b=${2:-0.2}; seeds=${3:-3}
sim="lagbench simulate --system double_pendulum --set friction=$b --rate 100 --noise 0.001 --dropped 0.02"
$sim --trajectories 400 --duration 1 --seed 0 --out "$out/data/train.csv"
$sim --trajectories 8 --duration 4 --seed 1 --out "$out/data/test.csv"
fit="lagbench fit --data $out/data/train.csv --test $out/data/test.csv --system double_pendulum --angle-wrap --quiet"
for ((s = 0; s < seeds; s++)); do
  $fit --model baseline --seed "$s" --out "$out/s$s-baseline"
  $fit --model lnn --dissipation off --steps 23437 --seed "$s" --out "$out/s$s-lnn"
  $fit --model lnn --dissipation --steps 23437 --seed "$s" --out "$out/s$s-lnn_dissipative"
done
python "$(dirname "$0")/summary.py" "$out" "$b"
