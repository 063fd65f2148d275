"""The cost of one call into the compiled exchange from Python, by route: ctypes (the standard library) and
cffi (ABI mode, the same shared library), on the kernel's smallest entry point (``cf_weights``: the Lagrange
weights of three points, a few dozen flops), with the arguments prepared once as the master prepares them.

    .venv/bin/python benchmarks/kernel_call_cost.py [--calls 200000]

Prints and saves benchmarks/results/kernel_call_cost.md (CPU time per call, best of 5).  Not a test.
"""
from __future__ import annotations

import argparse
import ctypes
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def per_call(fn, calls: int) -> float:
    best = float("inf")
    for _ in range(5):
        c0 = time.process_time()
        for _ in range(calls):
            fn()
        best = min(best, (time.process_time() - c0) / calls)
    return best * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200000)
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    from cranefmu.master import kernel

    lib = kernel.library()
    if lib is None:
        raise SystemExit(f"no compiled exchange here: {kernel.why_not}")
    ts, w1, w2 = np.array([0.0, 0.5, 1.0]), np.zeros(3), np.zeros(3)
    dp = ctypes.POINTER(ctypes.c_double)
    args = (ts.ctypes.data_as(dp), 3, 1.0, w1.ctypes.data_as(dp), w2.ctypes.data_as(dp))
    rows = [("ctypes (argtypes declared)", per_call(lambda: lib.cf_weights(*args), a.calls))]
    try:
        import cffi

        ffi = cffi.FFI()
        ffi.cdef("void cf_weights(const double *ts, int k, double t, double *w1, double *w2);")
        flib = ffi.dlopen(lib._name)
        cargs = (ffi.cast("double *", ts.ctypes.data), 3, 1.0, ffi.cast("double *", w1.ctypes.data),
                 ffi.cast("double *", w2.ctypes.data))
        rows.append(("cffi, ABI mode", per_call(lambda: flib.cf_weights(*cargs), a.calls)))
    except ImportError:
        rows.append(("cffi, ABI mode", float("nan")))
    rows.append(("an empty Python call (for scale)", per_call(lambda: None, a.calls)))
    lines = ["# One call into the compiled exchange, by route", "",
             f"`python benchmarks/kernel_call_cost.py --calls {a.calls}`: CPU time per call of `cf_weights` "
             "(best of 5 loops).", "", "| route | us per call |", "| --- | --- |"]
    lines += [f"| {name} | {us:.3f} |" for name, us in rows]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "kernel_call_cost.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
