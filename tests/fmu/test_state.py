"""FMU state get/set/serialize covers every internal state: save, run N steps, restore, run the
same N steps again gives bitwise the same outputs, through getFMUstate/setFMUstate and through
serializeFMUstate/deserializeFMUstate; a serialized state also carries over to a fresh instance,
initialized with default parameters, in another process.

pythonfmu allows one instance of an FMU per process (a second fmi2Instantiate of the same FMU
segfaults, measured with fmpy 0.3.32 / pythonfmu 0.7.0), so each run is its own spawned child."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu_support.model_cases import CASES

H, N_BEFORE, N_AFTER = 1e-2, 15, 25


def _run(fmu, t: float, n: int) -> np.ndarray:
    names = fmu.outputs()
    rows = []
    for _ in range(n):
        fmu.fmu.doStep(t, H)
        t += H
        rows.append(fmu.get(names))
    return np.array(rows)


def _save_run_restore(case_id: str) -> dict:
    from cranefmu_support.fmu_child import session

    case = next(c for c in CASES if c.id == case_id)
    with session() as open_fmu:
        a = open_fmu(case.fmu)
        a.start(case.fmu_params)      # initialized at rest with the default inputs ...
        a.set(case.inputs)            # ... then the case inputs move the states
        _run(a, 0.0, N_BEFORE)
        t = N_BEFORE * H
        state = a.fmu.getFMUState()
        blob = bytes(a.fmu.serializeFMUState(state))
        first = _run(a, t, N_AFTER)
        a.fmu.setFMUState(state)
        again = _run(a, t, N_AFTER)
        restored = a.fmu.deserializeFMUState(blob)
        a.fmu.setFMUState(restored)
        from_blob = _run(a, t, N_AFTER)
        a.fmu.freeFMUState(state)
        a.fmu.freeFMUState(restored)
        return dict(first=first, again=again, from_blob=from_blob, blob=blob)


def _resume_elsewhere(fmu_name: str, blob: bytes) -> np.ndarray:
    from cranefmu_support.fmu_child import session

    with session() as open_fmu:
        b = open_fmu(fmu_name)
        b.start()  # default parameters and inputs: everything must come from the blob
        b.fmu.setFMUState(b.fmu.deserializeFMUState(blob))
        return _run(b, N_BEFORE * H, N_AFTER)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_restored_state_repeats_the_same_numbers(built, case):
    from cranefmu_support.fmu_child import in_child

    r = in_child(_save_run_restore, case.id)
    first = r["first"]
    if case.make().state_names():  # the outputs change over the N steps (the Kelvin-Voigt rope has no state:
        assert np.max(np.abs(first[-1] - first[0])) > 0.0  # there the fresh instance checks inputs and parameters)
    assert np.array_equal(first, r["again"]), "get/set FMU state does not repeat the run"
    assert np.array_equal(first, r["from_blob"]), "serialize/deserialize does not repeat the run"
    other = in_child(_resume_elsewhere, case.fmu, r["blob"])
    assert np.array_equal(first, other), "a serialized state does not carry over to a fresh instance"


def _restore_undoes_a_tunable_change() -> dict:
    from cranefmu_support.fmu_child import session

    case = next(c for c in CASES if c.id == "chassis")
    with session() as open_fmu:
        a = open_fmu(case.fmu)
        a.start(case.params)
        a.set(case.inputs)
        t = N_BEFORE * H
        _run(a, 0.0, N_BEFORE)
        state = a.fmu.getFMUState()
        first = _run(a, t, N_AFTER)
        a.fmu.setFMUState(state)
        a.set({"damping": 4.05e4})     # tunable: the model is rebuilt with a tenth of the soil damping
        changed = _run(a, t, N_AFTER)
        a.fmu.setFMUState(state)        # the saved damping comes back, and the model built from it
        again = _run(a, t, N_AFTER)
        a.fmu.setFMUState(state)        # unchanged parameters: the model is kept (same numbers)
        kept = _run(a, t, N_AFTER)
        a.fmu.freeFMUState(state)
        return dict(first=first, changed=changed, again=again, kept=kept)


def test_restore_brings_back_the_tunable_parameters_model(built):
    """setFMUstate keeps the built model only while the restored parameters equal the current ones
    (a rollback then costs no rebuild); a tunable parameter changed since the save is restored with
    its model."""
    from cranefmu_support.fmu_child import in_child

    r = in_child(_restore_undoes_a_tunable_change)
    assert np.max(np.abs(r["changed"] - r["first"])) > 0.0
    assert np.array_equal(r["first"], r["again"])
    assert np.array_equal(r["first"], r["kept"])
