#!/usr/bin/env bash
# The extension of docs/lab/fit_budget_study.md (registered there before these runs): a second fresh data draw
# (simulate seeds 22 and 23, the same design), fit seeds 12-15, the baseline and the dissipative LNN at the
# frozen budget (the kind's defaults, nothing else set); two fits at a time on two cores. Then the paired
# decision over these four seeds and the study's first two.
#   bash docs/lab/fit_budget_study/more_seeds.sh OUT FIRST_TEST_OUT
set -euo pipefail
out=${1:?give a results folder}
first=${2:?give the results folder of run.sh}
sim="lagbench simulate --system double_pendulum --set friction=0.2 --rate 100 --noise 0.001 --dropped 0.02"
[ -f "$out/data/train.csv" ] || $sim --trajectories 400 --duration 1 --seed 22 --out "$out/data/train.csv"
[ -f "$out/data/test.csv" ] || $sim --trajectories 8 --duration 4 --seed 23 --out "$out/data/test.csv"
fit="lagbench fit --data $out/data/train.csv --test $out/data/test.csv --system double_pendulum --angle-wrap --quiet"
chain() {   # one seed after the other, each seed's two forms in turn
  for s in "$@"; do
    $fit --model lnn --dissipation --seed "$s" --out "$out/s$s-lnn_dissipative" > "$out/log_s$s-lnn_dissipative.txt" 2>&1
    $fit --model baseline --seed "$s" --out "$out/s$s-baseline" > "$out/log_s$s-baseline.txt" 2>&1
  done
}
mkdir -p "$out"
chain 12 14 & chain 13 15 & wait
python "$(dirname "$0")/paired.py" "$first" "$out"
