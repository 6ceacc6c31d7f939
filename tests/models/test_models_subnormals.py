"""lagbench's PyTorch flushes subnormal floats to zero in every thread, as XLA does on the CPU
(`models.torch.subnormals`), from its import on and in a run's workers; PyTorch alone keeps them."""
import json
import subprocess
import sys

import numpy as np

# float32's smallest normal number times 0.25 over 2^22 entries on two threads: zero everywhere where every
# thread flushes subnormals; the values it keeps elsewhere
PROBE = """
import json, torch
torch.set_num_threads(2)
{setup}
x = torch.full((1 << 22,), torch.finfo(torch.float32).tiny) * 0.25
out = {{"nonzero": int(x.count_nonzero()), "threads": torch.get_num_threads()}}
{more}
print(json.dumps(out))
"""


def _probe(setup="", more=""):
    code = PROBE.format(setup=setup, more=more)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_pytorch_alone_keeps_subnormals():
    """The control: without lagbench, PyTorch computes the subnormal results."""
    assert _probe() == {"nonzero": 1 << 22, "threads": 2}


def test_importing_lagbench_torch_models_flushes_them_in_every_thread_and_units_record_it():
    more = ("from lagbench.replication.run import environment as env\n"
            "from lagbench.models.torch import subnormals\n"
            "out.update(mode=subnormals.mode(), record=env.hardware()['torch_subnormals'])")
    got = _probe(setup="import lagbench.models.torch", more=more)
    assert got == {"nonzero": 0, "threads": 2, "mode": "flushed", "record": "flushed"}


def test_a_workers_start_flushes_them():
    got = _probe(setup="import os\nfrom lagbench.replication.run.environment import worker_start\n"
                       "worker_start(os.getppid())")
    assert got == {"nonzero": 0, "threads": 1}


def test_jax_flushes_them_too():
    """What the PyTorch setting matches: XLA on the CPU computes a subnormal result as zero."""
    import jax

    tiny = np.finfo(np.float32).tiny
    assert float(jax.jit(lambda v: v * np.float32(0.25))(np.float32(tiny))) == 0.0
