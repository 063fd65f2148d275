"""A run steps with BLAS/OpenMP pools of one thread (master/threads.py), and the caller's pools are as
they were afterwards."""
import pytest

from cranefmu.master.run import run

threadpoolctl = pytest.importorskip("threadpoolctl")


class _Threads:
    """Notes the BLAS pools' thread counts at every row."""

    def __init__(self):
        self.seen = set()

    def simulation_initialized(self, t, values):
        self.seen.update(i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas")

    def step_complete(self, t, h, values):
        self.simulation_initialized(t, values)


def test_run_pins_blas_to_one_thread_and_restores(oscillator_ssp):
    before = [i["num_threads"] for i in threadpoolctl.threadpool_info()]
    with threadpoolctl.threadpool_limits(limits=2):   # as on a machine with two cores or more
        outer = [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]
        seen = _Threads()
        run(oscillator_ssp, stop_time=0.01, step_size=1e-3, progress=False, observers=(seen,))
        assert seen.seen == {1}
        assert [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"] == outer
    assert [i["num_threads"] for i in threadpoolctl.threadpool_info()] == before
