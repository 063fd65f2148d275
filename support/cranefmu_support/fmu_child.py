"""Drive built FMUs through fmpy inside a spawned child process.

pythonfmu FMUs cannot be instantiated again in a process after an earlier instance was freed,
and every instance must be freed before the process exits; so each test hands a function to
:func:`in_child`, which runs it in a fresh spawned process, and that function opens its FMUs with
:func:`session`, which frees every instance it opened on the way out.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np



def in_child(func: Callable[..., Any], *args: Any) -> Any:
    """``func(*args)`` in a fresh spawned process (func must be importable); returns its result.
    A crash of the child raises BrokenProcessPool (a multiprocessing.Pool would wait forever)."""
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        return pool.submit(func, *args).result()


def in_pool(func: Callable[..., Any], *args: Any, timeout: float = 300.0) -> Any:
    """``func(*args)`` in a fresh spawned process; a hang fails after ``timeout`` s instead of blocking."""
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        return pool.apply_async(func, args).get(timeout=timeout)


class Fmu:
    """One instance of a built FMU with name-based set/get (wraps the master's FmuComponent)."""

    def __init__(self, name: str, workdir: Path, instance: str):
        from cranefmu import build as b
        from cranefmu.master.fmu import FmuComponent

        self.comp = FmuComponent(instance, b.FMU_DIR / f"{name}.fmu", workdir / instance)
        self.comp.instantiate()
        self.fmu = self.comp.fmu
        self.vars = self.comp.variables

    def set(self, values: dict[str, Any]) -> None:
        for k, v in values.items():
            var = self.vars[k]
            if var.type == "Real":
                self.fmu.setReal([var.valueReference], [float(v)])
            elif var.type == "Integer":   # a switch's name is turned into its code
                self.fmu.setInteger([var.valueReference], [int(self.comp.switches.get(k, {}).get(v, v))])
            else:
                self.fmu.setString([var.valueReference], [str(v)])

    def start(self, params: dict[str, Any] | None = None, inputs: dict[str, Any] | None = None,
              t0: float = 0.0) -> None:
        self.fmu.setupExperiment(startTime=t0)
        self.set(params or {})
        self.fmu.enterInitializationMode()
        self.set(inputs or {})
        self.fmu.exitInitializationMode()

    def get(self, names: list[str]) -> np.ndarray:
        out = []
        for k in names:
            var = self.vars[k]
            vr = [var.valueReference]
            out.append(self.fmu.getReal(vr)[0] if var.type == "Real" else self.fmu.getInteger(vr)[0])
        return np.array(out, dtype=float)

    def outputs(self) -> list[str]:
        return [v.name for v in self.comp.md.modelVariables if v.causality == "output"]

    @property
    def messages(self) -> list[str]:
        return self.comp.messages


@contextlib.contextmanager
def session() -> Iterator[Callable[[str, str | None], Fmu]]:
    """``with session() as open_fmu: f = open_fmu("Rope")``: every instance is freed at the end."""
    opened: list[Fmu] = []
    with tempfile.TemporaryDirectory(prefix="cranefmu_test_") as tmp:
        def open_fmu(name: str, instance: str | None = None) -> Fmu:
            f = Fmu(name, Path(tmp), instance or f"{name.lower()}{len(opened)}")
            opened.append(f)
            return f
        try:
            yield open_fmu
        finally:
            for f in opened:
                f.comp.free()
