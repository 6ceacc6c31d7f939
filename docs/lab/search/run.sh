#!/usr/bin/env bash
# Every declared search (docs/decisions/tuning_search.md) on the development split, quick's first, then full's
# where a claim trains longer in full than in quick (claims 1-2 through dp_loss, 3, 6, 7; the others run in
# full as in quick and take quick's choice). Each search appends its finished units to
# docs/lab/search/<claim>_<profile>/units.csv and writes its ledger there when whole; rerun this script on any
# machine after committing those files and only the missing units train.
#   bash docs/lab/search/run.sh [PROFILE ...]     (default: quick full)
#   JOBS=2 bash docs/lab/search/run.sh full       (a configuration's models in 2 worker processes)
set -euo pipefail
cd "$(dirname "$0")/../../.."
quick="hnn_energy wave_lgn delan_table1 delan_arm rel_coords init_study activation_study dp_loss delan_online"
full="rel_coords init_study activation_study dp_loss"
profiles=("$@")
[ ${#profiles[@]} -gt 0 ] || profiles=(quick full)
for profile in "${profiles[@]}"; do
  for claim in $([ "$profile" = quick ] && echo $quick || echo $full); do
    lagbench tune --claim "$claim" --profile "$profile" --frameworks jax --quiet --jobs "${JOBS:-1}" \
      --record "docs/lab/search/${claim}_${profile}/units.csv" --out "results/tune/${claim}_${profile}"
  done
done
