#!/usr/bin/env bash
# The searches that choose `full`'s protocols where a claim runs in full otherwise than in quick (claims 1-2
# through dp_loss, 3, 6, 7; the other claims, check 11 among them, train as in quick and take quick's adopted
# choices). Every one reads the development split only; each is resumable (rerun this script: finished
# configurations are read back, a training in flight continues from its snapshot). The searches are those of
# quick's tunes (docs/lab/tuning/README.md) at full's budget: dp_loss a width sweep for both models alike, the
# others four configurations per model, the pace studies over 8 development seeds.
#   bash docs/lab/full_tunes/run.sh [OUT]     (OUT: default results/tune)
set -euo pipefail
out=${1:-results/tune}
tune="lagbench tune --profile full --frameworks jax --quiet"
$tune --claim dp_loss --widths 0.5,2,4 --seeds 1 --out "$out/dp_loss_full"
$tune --claim rel_coords --configs 4 --seeds 1 --out "$out/rel_coords_full"
$tune --claim init_study --configs 4 --seeds 8 --out "$out/init_study_full"
$tune --claim activation_study --configs 4 --seeds 8 --out "$out/activation_study_full"
