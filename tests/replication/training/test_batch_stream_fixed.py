"""Part of the training data held over epochs (`Data.fixed`): with resample, the named state entries are the
epoch-0 draw's in every epoch while the others are redrawn, and the targets and weights are computed from
the states the batch holds (the original relativistic notebook: qdot from a fixed key, q and g every
epoch). The field is validated, and a protocol without it keeps its canonical form and key."""
import numpy as np
import pytest

from lagbench.replication.training.data import BatchStream
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.systems.closed_form import relativistic_acceleration

N, BATCH = 64, 16
DATA = Data("relativistic_iid", n_train=N, resample=True)
P = Protocol(data=DATA, steps=20, batch=BATCH, loss="l1_gamma", log_every=5)
HELD = P.replace(**{"data.fixed": ("qdot",)})


def _epoch(stream, epoch):
    stream.batch(epoch * (N // BATCH))
    return stream._pool


def test_fixed_entries_are_the_epoch_0_draws_and_the_rest_is_redrawn():
    held, plain = BatchStream(HELD, seed=3), BatchStream(P, seed=3)
    e0, e1, p0 = _epoch(held, 0), _epoch(held, 1), _epoch(plain, 0)
    for k in p0:
        assert np.array_equal(e0[k], p0[k]), k   # epoch 0 is plain resampling's epoch 0
    assert np.array_equal(e1["qdot"], e0["qdot"]) and not np.array_equal(e1["q"], e0["q"])
    assert not np.array_equal(e1["extra"], e0["extra"])   # the field g is redrawn
    qddot = relativistic_acceleration(e1["qdot"], e1["extra"])
    assert np.allclose(e1["target"], qddot, rtol=1e-12, atol=1e-300)
    assert np.array_equal(e1["weight"], 1.0 + 1.0 / np.sqrt(1.0 - e1["qdot"][:, 0] ** 2))
    assert not np.array_equal(_epoch(BatchStream(HELD, seed=4), 1)["qdot"], e1["qdot"])   # per seed


def test_the_field_is_validated_and_left_out_while_empty():
    assert "fixed" not in P.to_dict()["data"] and P.key() != HELD.key()
    assert HELD.to_dict()["data"]["fixed"] == ["qdot"] and Protocol.from_dict(HELD.to_dict()) == HELD
    with pytest.raises(ValueError, match="needs resample"):
        Data("relativistic_iid", n_train=N, fixed=("qdot",))
    with pytest.raises(ValueError, match="sorted, unique"):
        DATA.replace(fixed=("qdot", "q"))
    with pytest.raises(ValueError, match="not a state the system draws"):
        BatchStream(P.replace(**{"data.fixed": ("p",)}), seed=0).batch(0)
