"""A native model's functions (``include/cf_model.h``) called directly from Python, without the FMI
layer: what the model-level conformance tests compare against the Python model.

``load(name)`` compiles ``models/<name>.c`` with its generated tables header through cffi (setuptools'
compiler, into a temporary folder) and returns a :class:`NativeModel`.
"""
from __future__ import annotations

import importlib
import math
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

from .tables import model_header

HERE = Path(__file__).parent
CDEF = """
typedef struct CfModel { const double *p; double data[4096]; int n_states; char *msg; } CfModel;
int cf_check_params(CfModel *m);
int cf_prepare(CfModel *m);
int cf_initial_state(CfModel *m, const double *u, double *x);
void cf_derivatives(const CfModel *m, double t, const double *x, const double *u, double *dx);
void cf_outputs(const CfModel *m, double t, const double *x, const double *u, double *y);
int cf_frozen(const CfModel *m);
int cf_exact_applies(const CfModel *m);
int cf_exact_step(CfModel *m, double t, const double *x, double h, const double *u0, const double *r1,
                  const double *r2, double max_step, double *x1);
void cf_after_step(const CfModel *m, double t, double *x, const double *u);
const char *cf_state_name(const CfModel *m, int i);
extern const int cf_has_exact_step;
"""
FAIL_C = r"""
#include <stdarg.h>
#include <stdio.h>
int cf_fail(CfModel *m, const char *format, ...) {
    va_list ap; va_start(ap, format); vsnprintf(m->msg, 1024, format, ap); va_end(ap); return 1;
}
"""


def _physics(name: str):
    from ..adapter.fmi_adapter import CraneSlave  # noqa: F401  (the FMU scripts' base)
    module = {"Rope": "rope", "Drive": "drive", "Girder": "girder", "Pendulum": "pendulum", "Boom": "boom",
              "SlewingBoom": "slewing", "Chassis": "chassis", "Chassis4": "chassis4"}[name]
    mod = importlib.import_module(f"cranefmu.physics.{module}")
    return next(v for k, v in vars(mod).items() if k.endswith("Model") and isinstance(v, type)
                and v.__module__ == mod.__name__ and k != "Model")


def _shared_sources() -> list[Path]:
    """The C files every model is compiled with (``models/cf_*.c``: linear step, repr, ...)."""
    return sorted((HERE / "models").glob("cf_*.c"))


@lru_cache(maxsize=None)
def _compiled(name: str, source_stamp: float):
    import cffi

    model = _physics(name)
    build = Path(tempfile.mkdtemp(prefix=f"cf_native_{name}_"))
    (build / f"{name}_tables.h").write_text(model_header(model, name))
    ffi = cffi.FFI()
    ffi.cdef(CDEF)
    module = f"_cf_model_{name}"
    source = (HERE / "models" / f"{name}.c").read_text()
    shared = [str(f) for f in _shared_sources()]   # models/cf_*.c: compiled into every model
    ffi.set_source(module, '#include "cf_model.h"\n' + FAIL_C + source, sources=shared,
                   include_dirs=[str(HERE / "include"), str(build), str(HERE / "models")],
                   extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off", "-Wall"], libraries=["m"])
    lib_path = ffi.compile(tmpdir=str(build))
    sys.path.insert(0, str(build))
    try:
        mod = importlib.import_module(module)
    finally:
        sys.path.remove(str(build))
    return model, mod.ffi, mod.lib


class NativeModel:
    """One configured instance of a C model (parameters as the Python model's ``Params``)."""

    def __init__(self, name: str, params):
        stamp = max(f.stat().st_mtime for f in [HERE / "models" / f"{name}.c", *_shared_sources(),
                                                 *(HERE / "models").glob("cf_*.h")])
        self.model_cls, self.ffi, self.lib = _compiled(name, stamp)
        specs = self.model_cls.Params.field_specs()
        values = []
        for field, _, meta in specs:
            v = getattr(params, field)
            values.append(float(meta["choices"].index(v)) if meta.get("choices") else float(v))
        self._p = self.ffi.new("double[]", values)
        self._msg = self.ffi.new("char[]", 1024)
        self.m = self.ffi.new("CfModel *")
        self.m.p, self.m.msg = self._p, self._msg
        for fn in (self.lib.cf_check_params, self.lib.cf_prepare):
            if fn(self.m):
                raise ValueError(self.message())
        self.n_inputs, self.n_outputs = len(self.model_cls.inputs), len(self.model_cls.outputs)

    def message(self) -> str:
        return self.ffi.string(self._msg).decode()

    def _d(self, values, n=None):
        values = np.asarray(values, dtype=float)
        return self.ffi.new("double[]", values.tolist() or [0.0])

    def _out(self, n):
        return self.ffi.new("double[]", max(n, 1))

    def initial_state(self, u) -> np.ndarray:
        x = self._out(self.m.n_states)
        if self.lib.cf_initial_state(self.m, self._d(u), x):
            raise ValueError(self.message())
        return np.array([x[i] for i in range(self.m.n_states)])

    def derivatives(self, t, x, u) -> np.ndarray:
        dx = self._out(self.m.n_states)
        self.lib.cf_derivatives(self.m, t, self._d(x), self._d(u), dx)
        return np.array([dx[i] for i in range(self.m.n_states)])

    def outputs(self, t, x, u) -> np.ndarray:
        y = self._out(self.n_outputs)
        self.lib.cf_outputs(self.m, t, self._d(x), self._d(u), y)
        return np.array([y[i] for i in range(self.n_outputs)])

    def frozen(self) -> bool:
        return bool(self.lib.cf_frozen(self.m))

    def exact_applies(self) -> bool:
        return bool(self.lib.cf_exact_applies(self.m))

    def exact_step(self, t, x, h, u0, r1, r2, max_step):
        x1 = self._out(self.m.n_states)
        rc = self.lib.cf_exact_step(self.m, t, self._d(x), h, self._d(u0), self._d(r1), self._d(r2), max_step, x1)
        if rc < 0:
            raise FloatingPointError(self.message())
        return np.array([x1[i] for i in range(self.m.n_states)]) if rc == 1 else None

    def after_step(self, t, x, u) -> np.ndarray:
        xs = self._d(x)
        self.lib.cf_after_step(self.m, t, xs, self._d(u))
        return np.array([xs[i] for i in range(self.m.n_states)])

    def rk4_step(self, t0: float, x0: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray | None,
                 r2: np.ndarray | None, max_step: float) -> np.ndarray:
        """One communication step of the C model as :func:`cranefmu.adapter.fmi_adapter.advance` takes it with solver rk4:
        the project's own rk4 (:func:`~cranefmu.adapter.integrators.rk4_list` where the Python model steps plain floats,
        else :func:`~cranefmu.adapter.integrators.integrate`) on the C derivatives with the inputs u0 + s (r1 + s/2 r2)
        (a frozen model keeps its state), then the C after_step at the inputs of the step's end."""
        from ..adapter.integrators import integrate, rk4_list
        from ..physics.component import Model

        moving = r1 is not None and bool(np.any(r1) or np.any(r2))
        if self.frozen() or len(x0) == 0:
            x = np.asarray(x0, dtype=float)
        elif self.model_cls.derivatives_list is not Model.derivatives_list:   # Python steps plain floats
            u, d1, d2 = (np.asarray(v, dtype=float).tolist() for v in (u0, r1 if moving else u0, r2 if moving else u0))

            def f(ti, xi):
                if not moving:
                    return self.derivatives(ti, xi, u).tolist()
                s = ti - t0
                half = 0.5 * s
                return self.derivatives(ti, xi, [a + s * (b + half * c) for a, b, c in zip(u, d1, d2)]).tolist()
            x = np.array(rk4_list(f, t0, np.asarray(x0, dtype=float).tolist(), h, max_step))
        else:
            def f(ti, xi):
                if not moving:
                    return self.derivatives(ti, xi, u0)
                s = ti - t0
                return self.derivatives(ti, xi, u0 + s * (r1 + 0.5 * s * r2))
            x = integrate(f, t0, np.asarray(x0, dtype=float), h, "rk4", max_step=max_step)
        return self.after_step(t0 + h, x, u0 + h * (r1 + 0.5 * h * r2) if moving else u0)

    def state_name(self, i: int) -> str:
        return self.ffi.string(self.lib.cf_state_name(self.m, i)).decode()


def reference_expm(a: np.ndarray) -> np.ndarray:
    """exp(a) in numpy's longdouble (80-bit x87 on x86-64: 64-bit mantissa), Taylor to 30 terms after
    scaling to norm <= 1/8, then squaring: an independent reference ~1000x more precise than double."""
    a = np.asarray(a, dtype=np.longdouble)
    norm = float(np.max(np.sum(np.abs(a), axis=0)))
    s = max(0, math.ceil(math.log2(norm * 8.0))) if norm > 0.0 else 0
    b = a / np.longdouble(2.0) ** s
    term = np.eye(a.shape[0], dtype=np.longdouble)
    total = term.copy()
    for k in range(1, 30):
        term = term @ b / np.longdouble(k)
        total = total + term
    for _ in range(s):
        total = total @ total
    return total


def load(name: str, params) -> NativeModel:
    """The C model ``name`` (an FMU name: Rope, Drive, ...) configured with ``params``."""
    return NativeModel(name, params)
