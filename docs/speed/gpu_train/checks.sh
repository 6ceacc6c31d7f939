# the device checks of `--device gpu` (one call): versions, GPU parity tests, paper dp LNN throughput, paper dp estimate
export PYTHONPATH=$PWD PYTHONUNBUFFERED=1 LAGBENCH_CACHE=/tmp/lbc LAGBENCH_COMMIT=${COMMIT:-unknown}
D=${DEV:-gpu}
(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1; python3 -c "import jax, torch; print('jax', jax.__version__, jax.devices()); print('torch', torch.__version__, torch.cuda.is_available())") 2>&1 | tee $OUT/versions.txt
echo "== parity"; timeout 230 python3 -m pytest -q -p no:cacheprovider -W ignore::UserWarning -W ignore::FutureWarning -W ignore::RuntimeWarning tests/replication/training/test_training_parity_gpu.py tests/replication/training/test_device.py 2>&1 | tail -25 | tee $OUT/parity.txt
echo "== throughput"; timeout 160 python3 -m lagbench.speedstudy.train_throughput --device $D --steps ${STEPS:-200} --out $OUT/throughput.csv 2>&1 | tail -6
echo "== estimate"; timeout 150 python3 -m lagbench run --profile paper --claims dp_loss,dp_energy --device $D --dry-run --out /tmp/paperrun 2>&1 | tail -12 | tee $OUT/paper_estimate.txt
