"""Declared output dependencies (Signal.depends_on -> ModelStructure/Outputs) match the physics:
an output does not move when an input it does not declare is perturbed, and every declared input
moves its output in some configuration.  The built modelDescription.xml says the same."""
from __future__ import annotations

import numpy as np
import pytest
from fmpy import read_model_description

from cranefmu_support.model_cases import CASES

MODELS = sorted({c.model for c in CASES}, key=lambda m: m.__name__)
# 0/1 flags change only when a threshold is crossed; for them only the "undeclared: no change" half
FLAGS = {"slack", "lifted", "tipping"}


def generic_state(case, rng: np.random.Generator) -> np.ndarray:
    """The initial state of the case, moved off equilibrium by about 1 %."""
    m = case.make()
    x = m.initial_state(case.u())
    return x + rng.normal(0.0, 1.0, x.shape) * (0.01 * np.abs(x) + 1e-3)


def sensitivities(case, rng):
    """{(output, input): changed?} for one case: each input nudged by 1e-4 (1 + |u|)."""
    m = case.make()
    u = case.u()
    x = generic_state(case, rng)
    t = 0.3 * case.t_end
    x = m.after_step(t, x, u)
    y = m.output_values(t, x, u)
    out = {}
    for i, s_in in enumerate(m.inputs):
        u2 = u.copy()
        u2[i] += 1e-4 * (1.0 + abs(u[i]))
        y2 = m.output_values(t, x, u2)
        for j, s_out in enumerate(m.outputs):
            out[s_out.name, s_in.name] = bool(y2[j] != y[j])
    return out


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.__name__)
def test_declared_feedthrough_is_honest(model):
    rng = np.random.default_rng(7)
    changed: dict[tuple[str, str], bool] = {}
    for case in (c for c in CASES if c.model is model):
        for _ in range(3):
            for k, v in sensitivities(case, rng).items():
                changed[k] = changed.get(k, False) or v
    declared = {(s.name, d) for s in model.outputs for d in s.depends_on}
    undeclared_moves = sorted(k for k, v in changed.items() if v and k not in declared)
    assert not undeclared_moves, f"outputs move with inputs they do not declare: {undeclared_moves}"
    never_moves = sorted(k for k in declared if not changed.get(k) and k[0] not in FLAGS)
    assert not never_moves, f"declared dependencies without effect: {never_moves}"


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.__name__)
def test_model_description_lists_the_declared_dependencies(built, model):
    md = read_model_description(str(built / f"{model.__name__.removesuffix('Model')}.fmu"))
    names = [v.name for v in md.modelVariables]
    listed = {names[md.modelVariables.index(u.variable)]: {d.name for d in u.dependencies} for u in md.outputs}
    for s in model.outputs:
        assert listed[s.name] == set(s.depends_on), s.name


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.__name__)
def test_initial_state_inputs_are_declared(model):
    """At initialization every output may depend on the inputs the initial state is computed from
    (Model.initial_state_inputs -> ModelStructure/InitialUnknowns): the declaration is exact."""
    used = set()
    for case in (c for c in CASES if c.model is model):
        m, u = case.make(), case.u()
        x = m.initial_state(u)
        for i, s in enumerate(m.inputs):
            u2 = u.copy()
            u2[i] += 1e-4 * (1.0 + abs(u[i]))
            if not np.array_equal(m.initial_state(u2), x):
                used.add(s.name)
    assert used == set(model.initial_state_inputs)


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.__name__)
def test_initial_unknowns_list_feedthrough_initial_state_inputs_and_parameters(built, model):
    md = read_model_description(str(built / f"{model.__name__.removesuffix('Model')}.fmu"))
    params = {v.name for v in md.modelVariables if v.causality == "parameter"}
    listed = {u.variable.name: {d.name for d in u.dependencies} for u in md.initialUnknowns}
    for s in model.outputs:
        assert listed[s.name] == set(s.depends_on) | set(model.initial_state_inputs) | params, s.name
