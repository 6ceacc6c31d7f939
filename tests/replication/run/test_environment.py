"""What a result records of the machine: the CPU's vector features, which decide the kernels' rounding."""
from lagbench.replication.run.environment import cpu_description, hardware

ZEN4 = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: 25
model\t\t: 17
model name\t: AMD EPYC 9454P 48-Core Processor
flags\t\t: fpu sse sse2 sse4_1 sse4_2 avx avx2 fma avx512f avx512bw avx512vl avx512_bf16 sha_ni

processor\t: 1
model name\t: some other core
flags\t\t: fpu
"""


def test_the_first_processors_model_and_vector_features_are_read():
    d = cpu_description(ZEN4)
    assert d == {"cpu": "AMD EPYC 9454P 48-Core Processor", "cpu_model": "family 25 model 17",
                 "cpu_features": "sse4_2 avx avx2 fma avx512f avx512bw avx512vl avx512_bf16"}


def test_two_hosts_that_round_differently_are_told_apart():
    avx2_only = ZEN4.replace(" avx512f avx512bw avx512vl avx512_bf16", "").replace("model\t\t: 17", "model\t\t: 1")
    a, b = cpu_description(ZEN4), cpu_description(avx2_only)
    assert a["cpu_features"] != b["cpu_features"] and b["cpu_features"] == "sse4_2 avx avx2 fma"
    assert b["cpu_model"] == "family 25 model 1"


def test_missing_fields_give_empty_strings_not_an_error():
    assert cpu_description("") == {"cpu": "", "cpu_model": "", "cpu_features": ""}
    assert cpu_description("processor\t: 0\nflags\t\t: avx2\n")["cpu_features"] == "avx2"


def test_this_machine_records_strings_the_report_can_sort():
    hw = hardware()
    assert {"cpu", "cpu_model", "cpu_features", "cores", "gpu", "platform"} <= set(hw)
    assert all(isinstance(hw[k], str) for k in ("cpu", "cpu_model", "cpu_features"))
    assert hw["cpu"]
