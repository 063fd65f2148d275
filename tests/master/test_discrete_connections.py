"""Integer, Boolean and Enumeration connections between FMUs (issue 35): a zero-order hold at every
exchange, the Real exchange untouched.  Two Flags FMUs (tests/c_fmu/flags.c: each output is its input,
of the same type, updated as soon as the input is set) stepped by the Jacobi exchange, their inputs
driven between steps."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.master.coupled import Coupling
from cranefmu.master.extracted import extracted_scene
from cranefmu.master.initialization import initialize

REAL = [("a", "Real_output", "b", "Real_input")]
DISCRETE = [("a", "Enumeration_output", "b", "Integer_input"),   # Enumeration -> Integer
            ("a", "Boolean_output", "b", "Boolean_input"),
            ("b", "Integer_output", "a", "Integer_input")]      # and back: a loop through feedthrough


@pytest.fixture(scope="module")
def flags_fmu(tmp_path_factory):
    from c_fmu.flags import build, compiler

    if compiler() is None:
        pytest.skip("no C compiler")
    return build(tmp_path_factory.mktemp("flags") / "Flags.fmu")


def driven_rows(fmu, tmp_path, connections, steps=8, h=0.1, compiled=True):
    """Per step k the source a's unconnected inputs get new values (Real sin(k), Enumeration 10 + 3 k,
    Boolean k odd), then one Jacobi step (Coupling.jacobi_step: every FMU steps, then the exchange;
    ``compiled``: in the kernel where it can run, else in Python); returns (the Real outputs per row, the
    discrete outputs per row by name, whether the kernel ran)."""
    from cranefmu_support.foreign_ssp import write_ssp

    ssp = write_ssp(tmp_path / f"two_{len(connections)}.ssp", {"a": fmu, "b": fmu}, connections)
    workdir, scene = extracted_scene(ssp)
    c = Coupling(scene, workdir, 0)
    c.compiled = compiled
    try:
        initialize(c, 0.0, {}, 1e-10)
        a = c.by_name["a"]
        reals, flags = [], []
        for k in range(steps):
            a.fmu.setReal([0], [math.sin(k)])
            a.fmu.setInteger([2], [10 + 3 * k])
            a.fmu.setBoolean([0], [k % 2 == 1])
            c.jacobi_step(k * h, h)
            c.flags()
            row = c.outputs()
            reals.append(row[:c.n_real])
            flags.append(dict(zip(c.flag_names, c.flag_value.tolist())))
        return np.array(reals), flags, c.kernel() is not None
    finally:
        c.free()


def test_discrete_values_are_held_from_exchange_to_exchange_and_reals_do_not_change(flags_fmu, tmp_path):
    reals, rows, compiled = driven_rows(flags_fmu, tmp_path, REAL + DISCRETE)
    from cranefmu.master import kernel

    assert compiled == (kernel.library() is not None)   # the kernel moves the discrete values too
    python_reals, python_rows, ran = driven_rows(flags_fmu, tmp_path, REAL + DISCRETE, compiled=False)
    assert not ran and python_rows == rows and np.array_equal(python_reals.view(np.int64), reals.view(np.int64))
    for k, row in enumerate(rows):
        # each exchange: b's input gets a's value after the step (b's output is its input, set at once)
        assert row["b.Integer_output"] == row["a.Enumeration_output"] == 10 + 3 * k
        assert row["b.Boolean_output"] == row["a.Boolean_output"] == k % 2
        # every source is read before any input is set: a gets b's value of the exchange before
        before = rows[k - 1]["b.Integer_output"] if k else 1.0   # b's Integer_input after initialization:
        assert row["a.Integer_output"] == before                  # a's Enumeration start, 1
    plain, plain_rows, _ = driven_rows(flags_fmu, tmp_path, REAL)
    assert np.array_equal(reals.view(np.int64), plain.view(np.int64))   # the Real part, bit for bit
    assert reals[3, 1] == math.sin(3)                                  # and it moved
    assert plain_rows[3]["b.Integer_output"] == 0.0                     # unconnected: b's start


def test_a_discrete_connection_with_a_linear_transformation_is_refused_in_one_line():
    from cranefmu.errors import SceneError
    from cranefmu.master.discrete_links import check_discrete
    from cranefmu.master.scene import ConnectionSpec

    c = ConnectionSpec("a", "Integer_output", "b", "Integer_input", factor=2.0, transformed=True)
    with pytest.raises(SceneError) as err:
        check_discrete(c, "Integer", "Integer")
    assert str(err.value) == ("connection a.Integer_output -> b.Integer_input: Integer values with factor 2 and "
                              "offset 0; allowed: none (a LinearTransformation converts Real values only)")
    check_discrete(ConnectionSpec("a", "Enumeration_output", "b", "Integer_input", transformed=True),
                   "Enumeration", "Integer")   # an identity transformation is no conversion
