"""planner.single_threaded: one numba thread inside the block, the count given back on the way out."""

import numba
import pytest

from footfall.planner import single_threaded


def test_single_threaded_runs_on_one_thread_and_gives_the_count_back_even_on_an_error():
    before = numba.get_num_threads()
    with single_threaded():
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with pytest.raises(RuntimeError, match="inside"):
        with single_threaded():
            raise RuntimeError("inside")
    assert numba.get_num_threads() == before
