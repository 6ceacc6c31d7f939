#!/usr/bin/env bash
# The registered study of docs/lab/recording_defaults.md on the development files (the issue's recordings:
# friction 0.2, 100 Hz, 0.5 degree of noise, 2 % dropped frames; simulate seeds 30 and 31): for fit seeds
# SEEDS, the LNN at the kind's default budget (3 x steps on a trajectory file, its restarts and fallback), the
# LNN at a third of it (--steps 23437 --restart-fallback 0) and the baseline at its defaults, each with
# periodic inputs and dissipation chosen by default; the study's second item, derivatives of degree 5 against
# the default 3 (the window chosen for each alike), as lnn_1x_p5 and baseline_p5; one folder per arm and seed
# (a rerun reuses finished fits).
#   bash docs/lab/recording_defaults/run.sh OUT "0 1 2" [ARMS]
#   ARMS: any of lnn_1x lnn_3x baseline lnn_1x_p5 baseline_p5 lnn_1x_even lnn_half_even (the last two: the
#   Lagrangian even in qdot, --even-velocity, at the 1 x steps and at half of them, the 1 x arm's network work)
#   and lnn (the LNN at the fit's defaults, whatever they are); delan (DeLaN at its defaults); the filtered
#   acceleration loss (--loss-target filtered): delan_filtered, baseline_filtered at their defaults, and
#   lnn_filtered_matched, the LNN at its defaults with its batches divided by the 9 frames a row costs at the
#   development file's window 11 (--batch 28 --restart-batch 4: the defaults' work a step)
#   NOISE=0.001 bash ... : the same recordings at another position noise in radians (default 0.0087, 0.5 degree)
#   DATA_SEEDS="40 41" bash ... : other simulate seeds for the training and the test file (default: 30 31)
set -euo pipefail
out=${1:?give a results folder}
seeds=${2:-0 1 2}
arms=${3:-lnn_1x baseline lnn_3x}
noise=${NOISE:-0.0087}
sim="lagbench simulate --system double_pendulum --set friction=0.2 --rate 100 --noise $noise --dropped 0.02"
read -r train_seed test_seed <<< "${DATA_SEEDS:-30 31}"
[ -f "$out/data/train.csv" ] || $sim --trajectories 400 --duration 1 --seed "$train_seed" --out "$out/data/train.csv"
[ -f "$out/data/val.csv" ] || $sim --trajectories 8 --duration 4 --seed "$test_seed" --out "$out/data/val.csv"
fit="lagbench fit --data $out/data/train.csv --test $out/data/val.csv --system double_pendulum --quiet"
for s in $seeds; do
  for arm in $arms; do
    case $arm in
      lnn_1x) $fit --model lnn --steps 23437 --restart-fallback 0 --seed "$s" --out "$out/s$s-lnn_1x" ;;
      lnn_3x) $fit --model lnn --seed "$s" --out "$out/s$s-lnn_3x" ;;
      baseline) $fit --model baseline --seed "$s" --out "$out/s$s-baseline" ;;
      lnn_1x_p5) $fit --model lnn --steps 23437 --restart-fallback 0 --polyorder 5 --seed "$s" --out "$out/s$s-lnn_1x_p5" ;;
      baseline_p5) $fit --model baseline --polyorder 5 --seed "$s" --out "$out/s$s-baseline_p5" ;;
      lnn) $fit --model lnn --seed "$s" --out "$out/s$s-lnn" ;;
      lnn_1x_even) $fit --model lnn --steps 23437 --restart-fallback 0 --even-velocity --seed "$s" --out "$out/s$s-lnn_1x_even" ;;
      lnn_half_even) $fit --model lnn --steps 11719 --restart-fallback 0 --even-velocity --seed "$s" --out "$out/s$s-lnn_half_even" ;;
      delan) $fit --model delan --seed "$s" --out "$out/s$s-delan" ;;
      delan_filtered) $fit --model delan --loss-target filtered --seed "$s" --out "$out/s$s-delan_filtered" ;;
      baseline_filtered) $fit --model baseline --loss-target filtered --seed "$s" --out "$out/s$s-baseline_filtered" ;;
      lnn_filtered_matched) $fit --model lnn --loss-target filtered --batch 28 --restart-batch 4 --seed "$s" --out "$out/s$s-lnn_filtered_matched" ;;
    esac
  done
done
