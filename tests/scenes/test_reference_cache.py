"""The session cache of monolithic references (tests/reference_cache.py) returns the arrays a direct
cranefmu.analysis.reference.solve gives, solves once per argument set, and keeps different arguments apart."""
import numpy as np

import reference_cache
from cranefmu.analysis.reference import solve

STOP = 0.05
TIMES = np.linspace(0.0, STOP, 11)


def test_cached_reference_is_the_direct_solve_solved_once_per_arguments():
    direct = solve("elastic_pendulum", STOP, TIMES, parameters={"pendulum.theta0": 0.1}, rtol=1e-6)
    before = len(reference_cache.SOLVES)
    first = reference_cache.solve("elastic_pendulum", STOP, TIMES, parameters={"pendulum.theta0": 0.1}, rtol=1e-6)
    first["pendulum.theta"][:] = np.nan                      # a caller's change stays its own
    again = reference_cache.solve("elastic_pendulum", STOP, TIMES.copy(), parameters={"pendulum.theta0": 0.1},
                                  rtol=1e-6)
    assert len(reference_cache.SOLVES) == before + 1
    assert set(again) == set(direct)
    for name, values in direct.items():
        assert np.array_equal(again[name], values), name     # bitwise: the same arrays
    other = reference_cache.solve("elastic_pendulum", STOP, TIMES, parameters={"pendulum.theta0": 0.2}, rtol=1e-6)
    assert len(reference_cache.SOLVES) == before + 2
    assert not np.array_equal(other["pendulum.theta"], direct["pendulum.theta"])
