"""The value checks written once (`lagbench.validate`), and that the model spec and the protocol read them alike."""
import math

import numpy as np
import pytest

from lagbench import validate as V
from lagbench.models import ModelSpec
from lagbench.replication.training.protocol import Data, Protocol


def test_a_count_is_an_integer_and_a_real_field_takes_one():
    assert [V.is_integer(v) for v in (8, np.int64(8), 8.0, np.float64(8.0), True, "8", None)] == [
        True, True, False, False, False, False, False]
    assert [V.is_real(v) for v in (1, 1.0, np.float32(0.5), np.int64(2), math.nan, math.inf, True, "1", None)] == [
        True, True, True, True, False, False, False, False, False]
    assert V.integer("n", np.int64(3), low=1) == 3 and type(V.integer("n", np.int64(3))) is int
    assert V.real("l2", 0) == 0 and type(V.real("l2", 0)) is int   # as given: a record that stores floats converts
    assert V.integers("hidden", [8, np.int64(4)], low=1) == (8, 4)


@pytest.mark.parametrize("call, message", [
    (lambda: V.integer("steps", 10.0, low=1), "steps must be an integer >= 1, got 10.0"),
    (lambda: V.integer("keep", 5, low=1, high=3), "keep must be an integer from 1 to 3, got 5"),
    (lambda: V.integers("hidden", (8.0,), low=1), "hidden must be a non-empty sequence of integers >= 1, got (8.0,)"),
    (lambda: V.integers("hidden", (), low=1), "hidden must be a non-empty sequence of integers >= 1, got ()"),
    (lambda: V.real("b1", 1.0, low=0, below=1), "b1 must be a finite number in [0, 1), got 1.0"),
    (lambda: V.real("l2", math.nan), "l2 must be a finite number, got nan"),
    (lambda: V.real("eps", -1, low=0), "eps must be a finite number >= 0, got -1"),
    (lambda: V.positive("lr", 0), "lr must be positive and finite, got 0"),
    (lambda: V.flag("keep", 1), "keep must be True or False, got 1"),
    (lambda: V.one_of("loss", "l3", ("l1", "mse")), "unknown loss 'l3'; valid: l1, mse"),
])
def test_a_refusal_names_the_field_what_it_takes_and_what_it_got(call, message):
    with pytest.raises(ValueError) as e:
        call()
    assert str(e.value) == message


def test_the_spec_and_the_protocol_refuse_a_float_count_alike():
    """hidden=(8.0,) and steps=10.0 are both refused, with the shared check's message."""
    with pytest.raises(ValueError, match=r"^hidden must be a non-empty sequence of integers >= 1, got \(8\.0,\)$"):
        ModelSpec(kind="lnn", dof=2, hidden=(8.0,))
    with pytest.raises(ValueError, match=r"^protocol steps must be an integer >= 1, got 10\.0$"):
        Protocol(data=Data("spring_iid", n_train=4), steps=10.0, batch=1)
    with pytest.raises(ValueError, match=r"^dof must be an integer >= 1, got 2\.0$"):
        ModelSpec(kind="lnn", dof=2.0)
    # a real field takes an int: the same protocol, the same key
    assert Protocol(data=Data("spring_iid", n_train=4), steps=10, batch=1, l2=0).key() == \
        Protocol(data=Data("spring_iid", n_train=4), steps=10, batch=1, l2=0.0).key()
