# The device checks docs/gpu.md lists as open (one call): seeds packed as one program on CUDA in both
# frameworks (the cohort tests, every `paper` program, on the GPU), two workers sharing one GPU
# (`run --jobs 2 --device gpu`, packed), and `paper`'s estimate with its seeds packed.
export PYTHONPATH=$PWD PYTHONUNBUFFERED=1 LAGBENCH_CACHE=/tmp/lbc XLA_PYTHON_CLIENT_PREALLOCATE=false
(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1; python3 -c "import jax, torch; print('jax', jax.__version__, jax.devices()); print('torch', torch.__version__, torch.cuda.is_available())") 2>&1 | tee $OUT/versions.txt
echo "== cohorts on the GPU"; LAGBENCH_DEVICE=gpu timeout 200 python3 -m pytest -q -p no:cacheprovider -m "slow or not slow" -W ignore::UserWarning -W ignore::FutureWarning tests/replication/training/test_paper_cohorts.py tests/replication/run/test_estimate_gpu.py tests/replication/training/test_training_parity_gpu.py 2>&1 | tail -15 | tee $OUT/cohorts.txt
echo "== two workers, one GPU"; /usr/bin/time -f "wall %e s" timeout 230 python3 -m lagbench run --profile quick --claims hnn_energy --frameworks jax,torch --device gpu --jobs 2 --quiet --out /tmp/packed 2>&1 | tail -12 | tee $OUT/packed_run.txt
python3 - <<'PY' 2>&1 | tee $OUT/packed_units.txt
import glob, json, collections
seen = collections.Counter()
for f in glob.glob("/tmp/packed/units/**/result.json", recursive=True):
    r = json.load(open(f)); c = r.get("cohort") or {}
    seen[(json.dumps(r.get("train_device")), bool(c.get("packed")), r.get("framework"))] += 1
print("units by (train_device, packed, framework):", dict(seen))
PY
cp /tmp/packed/summary/verdicts.json $OUT/ 2>/dev/null
echo "== paper estimate, packed"; timeout 270 python3 -m lagbench run --profile paper --claims dp_loss,dp_energy --device gpu --dry-run --jobs 1 --out /tmp/paperest 2>&1 | grep -v "custom jvp" | tail -14 | tee $OUT/paper_dp_estimate.txt
