"""A mixin for fmpy's slave classes (FMI 2.0 and 3.0) that remembers a status fatal and refuses every later call.

FMI 2.0 (section 2.1.3): after fmi2Fatal "it is not possible to call any other function" of the instance.  With
pythonfmu 0.7.0 this is a memory fault, not a formality: a Python exception inside any FMI call makes its wrapper
release the instance's Python object, its class and its message list (``cleanPyObject``) without forgetting the
pointers, and return fmi2Fatal; a later call on that instance (fmi2SetFMUstate, fmi2GetReal, fmi2DoStep, ...) works
on the freed object and corrupts memory Python has handed on, and the process crashes later in garbage collection
(tests/README.md, "Memory faults").  So once an instance has returned fmi2Fatal no call reaches its C code: fmpy's
wrappers raise :func:`fatal_instance_error` (here), the master's direct calls return fmi2Fatal without calling
(:meth:`.fmu.FmuComponent.stop_calls`), and the compiled exchange is dropped (:meth:`.coupled.Coupling.kernel`).
"""
from __future__ import annotations

FATAL = 4   # fmi2Fatal, fmi3Fatal
_ERROR: list = []   # the class FatalInstanceError, made at first use (fmpy is imported only when FMUs run)


def fatal_instance_error(function: str) -> Exception:
    """The error for an FMI function not called because its instance returned fmi2Fatal before: an fmpy
    ``FMICallException`` of status fatal (what the callers catch), class ``FatalInstanceError``."""
    if not _ERROR:
        from fmpy.fmi1 import FMICallException

        class FatalInstanceError(FMICallException):
            """An FMI function not called: its instance returned fmi2Fatal before."""

        _ERROR.append(FatalInstanceError)
    err = _ERROR[0](function=function, status=FATAL)
    err.args = (f"{function} not called: the instance returned fmi2Fatal before, after which FMI 2.0 allows "
                "no call on it",)
    return err


class FatalAware:
    """Mixin for fmpy's slave classes: remember a status fatal (:attr:`fatal`, :meth:`mark_fatal`), after which
    every FMI call through fmpy's wrappers raises :func:`fatal_instance_error` without reaching the FMU."""

    fatal = False
    #: called once, without arguments, when the instance first returns fmi2Fatal (:class:`.fmu.FmuComponent`
    #: stops its direct calls there)
    on_fatal = None

    def mark_fatal(self) -> None:
        """The instance returned fmi2Fatal: no FMI call may reach it any more."""
        if not self.fatal:
            self.fatal = True
            if self.on_fatal is not None:
                self.on_fatal()

    def _call(self, fname, *args):
        from fmpy.fmi1 import FMICallException

        if self.fatal:
            raise fatal_instance_error(fname)
        try:
            return super()._call(fname, *args)
        except FMICallException as err:
            if err.status == FATAL:
                self.mark_fatal()
            raise
