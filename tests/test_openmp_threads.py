"""YADE's OpenMP loops run in one thread under /usr/bin/python3, as under the `yade` launcher,
even where matplotlib.pyplot (which loads libgomp, and libgomp reads OMP_NUM_THREADS once, when
it loads) came first. With two threads and the other core busy, every parallel region waits for
a descheduled thread: 4,000 steps of a copper ore cascade took 148 s instead of 1.3 s."""
import os
import subprocess
import sys

import pytest

PROBE = """
import ctypes, os
{first}
from yadebreak.adapter import yade_api
print(ctypes.CDLL("libgomp.so.1", mode=os.RTLD_NOLOAD).omp_get_max_threads())
"""


@pytest.mark.yade
@pytest.mark.parametrize("first", ["import matplotlib; matplotlib.use('Agg'); "
                                   "import matplotlib.pyplot", "import yadebreak"])
def test_yade_runs_one_openmp_thread_whatever_loaded_libgomp_first(first):
    if (os.cpu_count() or 1) < 2:
        pytest.skip("one core: OpenMP starts one thread anyway")
    env = {k: v for k, v in os.environ.items() if k != "OMP_NUM_THREADS"}
    out = subprocess.run([sys.executable, "-c", PROBE.format(first=first)], env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    assert out[-1] == "1"
