"""The speed study's compiled PyTorch rows get one library per intra-op thread count they are timed at
(inductor fixes a kernel's OpenMP thread count when it compiles), and a call picks the current count's."""
import torch

from lagbench.speedstudy.evaluators import for_threads, per_thread_count
from lagbench.speedstudy.timing import torch_threads


def test_one_library_per_thread_count_and_the_current_one_runs():
    before, seen = torch.get_num_threads(), []
    libs = per_thread_count(lambda: seen.append(torch.get_num_threads()) or f"lib{seen[-1]}", counts=(1, 2))
    assert seen == [1, 2] and libs == {1: "lib1", 2: "lib2"}
    assert torch.get_num_threads() == before
    for n, want in ((1, "lib1"), (2, "lib2"), (4, "lib2")):  # a count not compiled: the nearest
        with torch_threads(n):
            assert for_threads(libs) == want
