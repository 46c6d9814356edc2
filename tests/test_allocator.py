"""planner._allocator: after importing the planner, arrays freed and allocated again cost no page faults."""

import os
import subprocess
import sys

import pytest

# In a fresh interpreter (the setting is process-wide): after importing the planner, frames that each
# allocate six arrays of 4-12 MB, their sizes changing from frame to frame, and free them at the end (as
# a crowd's frame does its local maps). The minor page faults of six frames after three.
PROBE = """
import resource, numpy as np
import footfall.planner
from footfall.planner._allocator import keep_freed_memory
def frame(k):
    arrays = [np.ones((1 + (k + j) % 3) << 19) for j in range(6)]
    return sum(a.size for a in arrays)
for k in range(3):
    frame(k)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for k in range(3, 9):
    frame(k)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before, keep_freed_memory())
"""


def _faults(env_value: str) -> tuple[int, bool]:
    env = dict(os.environ, FOOTFALL_KEEP_FREED_MEMORY=env_value)
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
    faults, applied = out.stdout.split()
    return int(faults), applied == "True"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc settings")
def test_arrays_freed_and_allocated_again_reuse_the_pages_and_the_opt_out_keeps_the_default():
    faults, applied = _faults("1")
    if not applied:
        pytest.skip("not glibc")
    # Six frames of 24-72 MB, 6,000-18,000 pages of 4 kB each: glibc's defaults give most of them back
    # to the kernel at the frees (18,348 faults here), and each comes back as a fault.
    assert faults < 100
    faults, applied = _faults("0")
    assert not applied
    assert faults > 5_000
