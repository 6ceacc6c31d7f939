#!/usr/bin/env bash
# The test part of docs/lab/fit_budget_study.md: fresh friction double-pendulum data (simulate seeds 20 and
# 21), fresh fit seeds (10, 11), every form at the budget the development split chose (the kind's defaults,
# nothing else set), a starved LNN (5 steps, no restarts); then the summary of docs/lab/fit_friction_dp.
#   bash docs/lab/fit_budget_study/run.sh OUT
set -euo pipefail
out=${1:?give a results folder}
sim="lagbench simulate --system double_pendulum --set friction=0.2 --rate 100 --noise 0.001 --dropped 0.02"
[ -f "$out/data/train.csv" ] || $sim --trajectories 400 --duration 1 --seed 20 --out "$out/data/train.csv"
[ -f "$out/data/test.csv" ] || $sim --trajectories 8 --duration 4 --seed 21 --out "$out/data/test.csv"
fit="lagbench fit --data $out/data/train.csv --test $out/data/test.csv --system double_pendulum --angle-wrap --quiet"
for s in 10 11; do
  $fit --model baseline --seed "$s" --out "$out/s$s-baseline"
  $fit --model lnn --dissipation off --seed "$s" --out "$out/s$s-lnn"
  $fit --model lnn --dissipation --seed "$s" --out "$out/s$s-lnn_dissipative"
done
$fit --model lnn --steps 5 --restarts 0 --seed 10 --out "$out/starved" || true
python "$(dirname "$0")/../fit_friction_dp/summary.py" "$out" 0.2
