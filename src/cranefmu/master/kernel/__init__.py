"""The compiled exchange: ``exchange.c`` built at first use into the per-user cache and loaded with ctypes.

Route: a plain C99 shared library compiled with setuptools' compiler (the one that builds extensions: no
compiler command line written here) and called through ctypes, from the standard library.  Measured
(benchmarks/results/kernel_call_cost.md): a ctypes call costs about 0.75 us more than a cffi one; the
kernel is called once per macro step (21-27 us a step in the loop, benchmarks/results/master_per_step.md)
or once per stretch of up to 256 steps, so cffi would save at most a few per cent of a step, for a
run-time dependency; ctypes it is.
The library is checked once per process against numpy: its extrapolation product must give numpy's
bits for every size in use (it reproduces OpenBLAS's gemv; another BLAS may differ), else the Python
exchange runs.  Without a compiler (or setuptools) the Python exchange runs: the same numbers, slower;
one line on stderr says so.
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("exchange.c")
DISABLE = "CRANEFMU_PYTHON_EXCHANGE"   # set (to anything but '' or '0'): always the Python exchange

_LIB: ctypes.CDLL | None = None
_TRIED = False
_CHECKED: set[int] = set()   # sizes whose product was checked against numpy
_FOLDER: list[Path] = []     # the library's folder in the cache (where the sizes checked are kept, :func:`_agreed_file`)
why_not = ""                 # why the compiled exchange is not used ('' when it is)


def _flags(compiler_type: str) -> list[str]:
    # the Python path's arithmetic: no contraction of a * b + c into an fma that numpy does not do;
    # CRANEFMU_SANITIZE (cranefmu.sanitize) adds a sanitizer's instrumentation, for finding memory faults
    from ...sanitize import sanitize_flags

    if compiler_type != "unix":
        return ["/O2", "/fp:precise"]
    return ["-O2", "-ffp-contract=off", "-std=c99", *sanitize_flags()]


def _build(target: Path) -> None:
    """Compile exchange.c into the shared library ``target`` (setuptools' compiler, atomic rename)."""
    from setuptools._distutils.ccompiler import new_compiler
    from setuptools._distutils.sysconfig import customize_compiler

    cc = new_compiler()
    customize_compiler(cc)
    with tempfile.TemporaryDirectory(dir=target.parent) as tmp:
        objects = cc.compile([str(SOURCE)], output_dir=tmp, extra_postargs=_flags(cc.compiler_type))
        built = Path(tmp) / target.name
        cc.link_shared_object(objects, str(built), libraries=["m"] if cc.compiler_type == "unix" else [],
                              extra_postargs=[f for f in _flags(cc.compiler_type) if f.startswith("-fsanitize")])
        os.replace(built, target)


def library() -> ctypes.CDLL | None:
    """The compiled kernel, built into the cache on first use; None where it cannot be (see :data:`why_not`)."""
    global _LIB, _TRIED, why_not
    if _TRIED:
        return _LIB
    _TRIED = True
    if os.environ.get(DISABLE, "") not in ("", "0"):
        why_not = f"{DISABLE} is set"
        return None
    from ...cache import cache_root, locked

    from ...sanitize import sanitize_flags

    sanitized = " ".join(sanitize_flags())   # an instrumented build is cached apart from the plain one
    digest = hashlib.sha256(SOURCE.read_bytes() + sys.platform.encode() + sanitized.encode()).hexdigest()[:16]
    folder = cache_root() / "kernel" / digest
    target = folder / ("cf_exchange" + (".dll" if sys.platform == "win32" else ".so"))
    try:
        if not target.is_file():
            with locked(folder):
                if not target.is_file():
                    _build(target)
        lib = ctypes.CDLL(str(target))
        _FOLDER[:] = [folder]
    except Exception as err:   # no compiler, no setuptools, a read-only cache: the Python exchange
        why_not = f"the compiled exchange could not be built ({type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''})"
        print(f"cranefmu: {why_not}; the exchange runs in Python (same results, slower)", file=sys.stderr)
        return None
    double_p, int_ = ctypes.POINTER(ctypes.c_double), ctypes.c_int
    lib.cf_dot_gemv.argtypes = [double_p, double_p, int_, int_, double_p]
    lib.cf_dot_gemv.restype = None
    lib.cf_weights.argtypes = [double_p, int_, ctypes.c_double, double_p, double_p]
    lib.cf_weights.restype = None
    lib.cf_jacobi_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, int_]
    lib.cf_jacobi_step.restype = int_
    lib.cf_jacobi_steps.argtypes = [ctypes.c_void_p, ctypes.c_void_p, int_, int_, ctypes.c_void_p]
    lib.cf_jacobi_steps.restype = int_
    lib.cf_gauss_seidel_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, int_]
    lib.cf_gauss_seidel_step.restype = int_
    lib.cf_exchange.argtypes = [ctypes.c_void_p, ctypes.c_double, int_]
    lib.cf_exchange.restype = int_
    lib.cf_plain_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double]
    lib.cf_plain_step.restype = int_
    lib.cf_evaluate.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, int_, int_, int_, int_,
                                int_, ctypes.c_void_p, int_, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
    lib.cf_evaluate.restype = int_
    _LIB = lib
    return lib


def agrees_with_numpy(lib: ctypes.CDLL, sizes: list[int], trials: int = 40) -> bool:
    """The kernel's extrapolation product gives numpy's ``w @ stack`` bit for bit for these sizes
    (random values over 12 decades, random point spacings, two and three points)."""
    from ..coupling import _lagrange_weights

    todo = sorted(set(sizes) - _CHECKED)
    if not todo:
        return True
    kept = _agreed_file() if lib is _LIB else None
    if kept is not None:   # sizes checked by an earlier process with this numpy and BLAS
        _CHECKED.update(_read_sizes(kept))
        todo = sorted(set(sizes) - _CHECKED)
        if not todo:
            return True
    rng = np.random.default_rng(34)
    ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))   # noqa: E731
    for n in todo:
        for k in (2, 3):
            for _ in range(trials):
                ts = sorted(rng.uniform(0.0, 1.0, k).tolist())
                t = ts[-1] + float(rng.uniform(0.0, 0.1))
                w1, w2 = _lagrange_weights(ts, t)
                c1, c2 = np.empty(k), np.empty(k)
                lib.cf_weights(ptr(np.array(ts)), k, t, ptr(c1), ptr(c2))
                if not (np.array_equal(c1, w1) and np.array_equal(c2, w2)):
                    return False
                stack = rng.normal(size=(k, n)) * 10.0 ** rng.uniform(-6, 6, size=(k, n))
                for w in (w1, w2):
                    out = np.empty(n)
                    lib.cf_dot_gemv(ptr(np.ascontiguousarray(w)), ptr(stack), k, n, ptr(out))
                    if not np.array_equal(out, w @ stack):
                        return False
    _CHECKED.update(todo)
    if kept is not None:
        _write_sizes(kept, _CHECKED | _read_sizes(kept))
    return True


def _agreed_file() -> Path | None:
    """The file of the sizes on which the library agrees with numpy, for this numpy and these BLAS libraries:
    beside the library, named by a digest of numpy's version and location and each loaded BLAS's name, version,
    CPU architecture (the kernels OpenBLAS chose) and file (threadpoolctl).  A cold ``cranefmu run`` then skips
    the check (0.02-0.2 s of CPU, more with more coupling sizes).  None without threadpoolctl (the BLAS is
    unknown: checked in every process)."""
    if not _FOLDER:
        return None
    try:
        from threadpoolctl import threadpool_info
    except ImportError:
        return None
    blas = sorted((i.get("internal_api"), i.get("version"), i.get("architecture"), i.get("filepath"))
                  for i in threadpool_info() if i.get("user_api") == "blas")
    key = hashlib.sha256(repr((np.__version__, np.__file__, sys.platform, blas)).encode()).hexdigest()[:16]
    return _FOLDER[0] / f"agrees_{key}.txt"


def _read_sizes(path: Path) -> set[int]:
    try:
        return {int(x) for x in path.read_text().split()}
    except (OSError, ValueError):   # none kept yet, or a damaged file: checked again
        return set()


def _write_sizes(path: Path, sizes: set[int]) -> None:
    """Whole or not at all (a rename); a cache that cannot be written only costs the check next time."""
    try:
        partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        partial.write_text("\n".join(str(n) for n in sorted(sizes)) + "\n")
        os.replace(partial, path)
    except OSError:
        pass
