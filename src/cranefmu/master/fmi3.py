"""FMI 3.0 co-simulation FMUs in the master: fmpy's FMU3Slave seen through the FMI 2.0 calls the
master makes (:class:`.fmu.FmuComponent`, :class:`.coupled.Coupling`).

What maps (FMI 3.0 standard, sec. 2.2 and 4): Float64 is the master's Real; the integer types are its
Integer; fmi3Boolean (a C bool) is read into the master's int arrays; fmi2SetupExperiment's start time
is handed to fmi3EnterInitializationMode; fmi3DoStep's event/terminate/early-return flags are
read and dropped (the FMU is instantiated without event mode or early return, so they stay false);
fmi3Reset, fmi3Get/SetFMUState as their FMI 2.0 counterparts.  An FMI 3.0 FMU cannot take input
derivatives in co-simulation (canInterpolateInputs is false here) and Float32, Binary and Clock
variables are not coupled or recorded; an integer parameter is set as Int32.
"""
from __future__ import annotations

import ctypes

from .process import FMI3_LOGGERS as _LOGGERS, Messages

INTEGERS = ("Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64")


def refuse_unsupported(md, where: str) -> None:
    """Refuse, at load, an input or output the master cannot read or set through fmi3GetInt32/
    fmi3GetFloat64/fmi3GetBoolean on one value: another integer type (Int8 ... UInt64, read as Int32
    the FMU refuses or the value is wrong) or an array (``<Dimension>``: the master reads one value).
    ``where`` names the component and file for the one-line message."""
    from ..errors import SceneError

    for v in md.modelVariables:
        if v.causality not in ("input", "output"):
            continue
        if getattr(v, "dimensions", None):
            raise SceneError(f"{where}: {v.causality} {v.name!r} is an array ({v.type} with "
                             f"{len(v.dimensions)} dimension(s)); not supported: the master couples and records "
                             "scalars only (docs/foreign_fmus.md)")
        if v.type in INTEGERS and v.type != "Int32":
            raise SceneError(f"{where}: {v.causality} {v.name!r} is {v.type}; not supported: the master reads "
                             "and sets FMI 3.0 integers as Int32 only (docs/foreign_fmus.md)")


def normalize(md) -> None:
    """Name an FMI 3.0 description's types as the master's (Float64 -> Real, integers -> Integer)."""
    for v in md.modelVariables:
        if v.type == "Float64":
            v.type = "Real"
        elif v.type in INTEGERS:
            v.type = "Integer"
    md.coSimulation.canInterpolateInputs = False


_SLAVE = None


def slave_class():
    """fmpy's FMU3Slave with the FMI 2.0 calls of the master (the class made once, on first use);
    ``instantiate(callbacks=messages)`` takes the instance's log (a :class:`.process.Messages`), filled by
    its log callback."""
    global _SLAVE
    if _SLAVE is not None:
        return _SLAVE
    from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64

    from .fatal_status import FatalAware

    class FMU3SlaveAsFmi2(FatalAware, FMU3Slave):   # fmpy binds the fmi3 functions of a class not named FMU1/FMU2
        start_time = 0.0

        def instantiate(self, loggingOn=False, callbacks=None):
            box = callbacks if callbacks is not None else Messages()

            def log(env, status, category, message):
                if status < 1:   # keep warning, discard, error, fatal
                    return
                box.add(message.decode(errors="replace") if isinstance(message, bytes) else str(message))

            super().instantiate(loggingOn=loggingOn, logMessage=log)
            _LOGGERS.append(self.logMessage)   # fmpy's ctypes wrapper of ``log``
            self._bind_fmi2()

        def _bind_fmi2(self) -> None:
            """FMI 2.0 signatures over the FMI 3.0 functions for the master's hot path."""
            f = self._functions
            get64, set64, do_step = f["fmi3GetFloat64"], f["fmi3SetFloat64"], f["fmi3DoStep"]
            get_int, get_bool = f["fmi3GetInt32"], f["fmi3GetBoolean"]
            set_int, set_bool = f["fmi3SetInt32"], f["fmi3SetBoolean"]
            flags = [fmi3Boolean() for _ in range(3)]
            last = fmi3Float64()
            refs = [ctypes.byref(x) for x in flags] + [ctypes.byref(last)]

            def get_boolean(c, vrs, n, values):
                out = (fmi3Boolean * n)()
                status = get_bool(c, vrs, n, out, n)
                for i in range(n):
                    values[i] = 1 if out[i] else 0
                return status

            f["fmi2GetReal"] = lambda c, vrs, n, values: get64(c, vrs, n, values, n)
            f["fmi2SetReal"] = lambda c, vrs, n, values: set64(c, vrs, n, values, n)
            f["fmi2DoStep"] = lambda c, t, h, no_prior: do_step(c, t, h, no_prior, *refs)
            f["fmi2GetInteger"] = lambda c, vrs, n, values: get_int(c, vrs, n, values, n)
            f["fmi2GetBoolean"] = get_boolean
            f["fmi2SetInteger"] = lambda c, vrs, n, values: set_int(c, vrs, n, values, n)
            f["fmi2SetBoolean"] = lambda c, vrs, n, values: set_bool(c, vrs, n, (fmi3Boolean * n)(*values), n)

        # --- the FMI 2.0 calls the master makes -------------------------------------------------
        def setupExperiment(self, tolerance=None, startTime=0.0, stopTime=None):
            self.start_time = startTime

        def enterInitializationMode(self, tolerance=None, startTime=None, stopTime=None):
            super().enterInitializationMode(startTime=self.start_time if startTime is None else startTime)

        def getReal(self, vr):
            return self.getFloat64(vr)

        def setReal(self, vr, values):
            self.setFloat64(vr, values)

        def setInteger(self, vr, values):
            self.setInt32(vr, values)

        def getFMUstate(self):
            return self.getFMUState()

        def setFMUstate(self, state):
            self.setFMUState(state)

        def freeFMUstate(self, state):
            self.freeFMUState(state)

    _SLAVE = FMU3SlaveAsFmi2
    return _SLAVE
