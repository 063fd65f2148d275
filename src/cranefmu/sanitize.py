"""The compiler's memory checks for the C this package compiles: ``CRANEFMU_SANITIZE=address`` adds
AddressSanitizer to the native FMUs (:mod:`cranefmu.native.build`) and to the compiled exchange
(:mod:`cranefmu.master.kernel`); unset (the default) adds nothing.

For finding memory faults only (tests/README.md, "Memory faults"): an instrumented library runs only in a
process that loads the sanitizer first, e.g.
``LD_PRELOAD=$(gcc -print-file-name=libasan.so) ASAN_OPTIONS=detect_leaks=0 PYTHONMALLOC=malloc``.
The kernel's instrumented build is cached apart from the plain one; native FMUs are rebuilt with
``cranefmu build --force`` (and again without the variable afterwards).
"""
from __future__ import annotations

import os

VARIABLE = "CRANEFMU_SANITIZE"
SANITIZERS = {"address": ["-fsanitize=address", "-fno-omit-frame-pointer", "-g"]}


def sanitize_flags() -> list[str]:
    """The GCC/Clang flags the variable asks for ([] when unset or empty); a value not in
    :data:`SANITIZERS` raises ValueError naming it."""
    value = os.environ.get(VARIABLE, "").strip()
    if not value:
        return []
    if value not in SANITIZERS:
        raise ValueError(f"{VARIABLE}={value!r} is not a sanitizer here: allowed {', '.join(SANITIZERS)} or unset")
    return list(SANITIZERS[value])
