"""Let a process that ran a pythonfmu FMU exit cleanly, from inside the FMU (any host, C or Python).

pythonfmu 0.7.0's binary (``binaries/linux64/<model>.so``, built from its PySlaveInstance.cpp) keeps the
interpreter guard ``PyState`` in a static ``std::shared_ptr``.  At process exit two things release it:

1. C++ registered the pointer's destructor with ``__cxa_atexit`` when the library was loaded: ``exit()``
   runs it first, the use count drops to 0 and the 128-byte control block is freed;
2. the library's ELF destructor ``onLibraryUnload`` -> ``finalizePythonInterpreter()`` (``pyState =
   nullptr``) runs later in ``_dl_fini`` on the destroyed pointer and decrements the use count inside the
   freed block (valgrind: "Invalid read of size 4 at finalizePythonInterpreter ... 8 bytes inside a block
   of size 128 free'd ... alloc'd by pythonfmu::createInstance").  When the block lies in glibc's unsorted
   bin that decrement hits its ``bk`` pointer, and the next ``free`` in a later destructor (numpy's
   libgfortran ``close_units``) aborts: ``free(): corrupted unsorted chunks``, exit 134.

The fix from our side: at the first instantiation in a process, register the library's own exported
``finalizePythonInterpreter`` as one more ``exit()`` handler (``__cxa_atexit``, no DSO: run at exit only).
Handlers run last-registered first, so it runs before step 1, while the pointer is alive: it empties
the pointer (and, with every instance freed, destroys ``PyState``, whose thread finalizes the interpreter
it started, with every library still loaded); steps 1 and 2 then find an empty pointer.  The library is
held open by a reference of ours, so the handler's code stays mapped (its C++ unique symbols make
``dlclose`` a no-op anyway).  In a Python host pythonfmu did not start the interpreter, and destroying
``PyState`` only joins its finished thread.  An instance still alive at exit keeps its own reference:
the interpreter is then not finalized, and nothing touches freed memory either.
"""
from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path

_REGISTERED: dict[str, ctypes.CDLL] = {}   # binary path -> our reference to it (keeps it mapped)
_RTLD_NOLOAD = getattr(os, "RTLD_NOLOAD", 4)


def binary_of(resources: str | None, model_identifier: str) -> Path | None:
    """The linux64 binary of the FMU whose ``resources`` folder pythonfmu passed (FMI 2.0's layout:
    ``<unzipdir>/resources`` beside ``<unzipdir>/binaries/linux64/<modelIdentifier>.so``), or None."""
    if not resources:
        return None
    path = Path(resources).parent / "binaries" / "linux64" / f"{model_identifier}.so"
    return path if path.is_file() else None


def release_guard_at_exit(binary: Path | None) -> bool:
    """Register ``binary``'s ``finalizePythonInterpreter`` as an exit handler (once per binary and process;
    module docstring).  Returns True when it is registered (now or before), False where it does not apply:
    not Linux, no binary, the binary not loaded in this process, or no such function (not pythonfmu 0.7's)."""
    if binary is None or not sys.platform.startswith("linux"):
        return False
    key = str(Path(binary).resolve())
    if key in _REGISTERED:
        return True
    try:   # only a library already in the process (the one running this code): never load a second copy
        lib = ctypes.CDLL(key, mode=_RTLD_NOLOAD)
        finalize = lib.finalizePythonInterpreter
    except (OSError, AttributeError):
        return False
    libc = ctypes.CDLL(None)
    register = libc.__cxa_atexit
    register.restype = ctypes.c_int
    register.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
    # a void(void) function called with one ignored pointer argument: harmless in the SysV x86-64 and
    # AArch64 calling conventions
    if register(ctypes.cast(finalize, ctypes.c_void_p), None, None) != 0:
        return False
    _REGISTERED[key] = lib
    return True
