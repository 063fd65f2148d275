"""One FMU instance in the master: value references resolved once, typed start values, batched calls."""
from __future__ import annotations

import atexit
import contextlib
import ctypes
import re
from pathlib import Path

import numpy as np

from ..errors import ParameterSetError, SceneError
from .fatal_status import FATAL, FatalAware, fatal_instance_error
from .settings import parse_bool
from .fmi_integer import fmi_integer
# the process-global state of the pythonfmu workarounds (the contract: .process)
from .process import EXTRACTED_MARK as _EXTRACTED, MODEL_DESCRIPTIONS as _MODEL_DESCRIPTIONS, Messages
from .process import in_place, instance_callbacks as _instance_callbacks

_EXCEPTION_LINE = re.compile(r"^[A-Za-z_][\w.]*(Error|Exception|Exit|Interrupt)\b.*")


def _check_binary(name: str, fmu_name: str, unzipdir: Path, identifier: str, fmi3: bool = False) -> None:
    """Refuse an FMU without a shared library for this platform, naming the platforms it has."""
    from fmpy import platform, platform_tuple, sharedLibraryExtension

    platform = platform_tuple if fmi3 else platform   # FMI 3.0 names binaries/ folders by platform tuple

    if (unzipdir / "binaries" / platform / (identifier + sharedLibraryExtension)).is_file():
        return
    have = sorted(p.name for p in (unzipdir / "binaries").iterdir() if p.is_dir()) \
        if (unzipdir / "binaries").is_dir() else []
    raise SceneError(f"component {name!r}: {fmu_name} has no binary for this platform ({platform}): it has "
                     f"{', '.join(have) or 'no binaries at all'}; rebuild the FMU here (cranefmu build)")


# pythonfmu binaries by path, each held open by this module until the interpreter exits
_PYTHONFMU_LIBRARIES: dict[str, ctypes.CDLL] = {}


def _hold_pythonfmu_library(dll) -> None:
    """Keep a pythonfmu binary loaded and release its interpreter guard before C's exit handlers run.

    pythonfmu 0.7.0's binary holds its ``PyState`` in a static ``std::shared_ptr`` that C++ destroys
    among ``exit()``'s handlers, and its ELF destructor ``finalizePythonInterpreter`` then resets that
    destroyed pointer in ``_dl_fini``: it decrements the use count inside the freed block (valgrind:
    "Invalid read of size 4 ... 8 bytes inside a block of size 128 free'd").  Its C++ unique symbols make
    fmpy's dlclose a no-op, so every process that instantiated one reaches that path; when the block has
    gone to glibc's unsorted bin the decrement hits its ``bk`` pointer and the process aborts at exit
    ("corrupted double-linked list").  Calling ``finalizePythonInterpreter`` from Python's ``atexit``
    empties the pointer while it is alive: the C++ destructor and the ELF destructor then find nothing.
    """
    path = dll._name
    if path in _PYTHONFMU_LIBRARIES or not hasattr(dll, "finalizePythonInterpreter"):
        return
    if not _PYTHONFMU_LIBRARIES:
        atexit.register(release_pythonfmu_libraries)
    held = ctypes.CDLL(path)   # our own reference: the code stays mapped even where dlclose could unload it
    held.finalizePythonInterpreter.restype = None
    held.finalizePythonInterpreter.argtypes = []
    _PYTHONFMU_LIBRARIES[path] = held


def release_pythonfmu_libraries() -> None:
    """Drop each held pythonfmu binary's interpreter guard (at exit; an instance still alive keeps its own
    reference, and a later instantiation makes a new guard)."""
    for held in _PYTHONFMU_LIBRARIES.values():
        held.finalizePythonInterpreter()


_SLAVE = None


def _slave_class():
    """fmpy's FMU2Slave that remembers a status fatal and refuses every later call: FMI 2.0 allows no further
    call on such an instance (measured with pythonfmu: fmi2Terminate/fmi2FreeInstance after a refused parameter
    made the process crash in garbage collection, 8 runs in 12; fmi2SetFMUstate after a failed fmi2GetReal, every
    run: :mod:`.fatal_status`), so :meth:`FmuComponent.free` skips it."""
    global _SLAVE
    if _SLAVE is None:
        from fmpy.fmi2 import FMU2Slave

        class FMU2SlaveFatalAware(FatalAware, FMU2Slave):  # fmpy finds the FMI functions by the 'FMU2' prefix
            pass

        _SLAVE = FMU2SlaveFatalAware
    return _SLAVE


_CALL_WRAPPERS: list = []   # active wrap_fmi_calls wrappers, innermost last

# (directory, model identifier) -> (fmpy slave, its callbacks, its log) of native cranefmu FMUs whose run
# ended: the instance terminated but alive, its library loaded with its functions resolved.  The next run's
# instance of that FMU is this one after fmi2Reset (loading a library and resolving its functions cost ~6 ms
# an FMU; fmi2Reset puts every value back to the start values fmi2Instantiate gives: native/fmi2/cf_fmi2.c)
_LOADED: dict[tuple[str, str], list] = {}
NATIVE_TOOL = "native FMI 2.0 layer"   # in the generationTool of cranefmu's native FMUs (native/description.py)


def keeps_library(md) -> bool:
    """Whether an FMU's loaded library is kept for later instances in this process: only cranefmu's own
    native FMI 2.0 FMUs (plain C, no global state; pythonfmu's binaries must load fresh, process.py)."""
    return md.fmiVersion == "2.0" and NATIVE_TOOL in (md.generationTool or "")


@contextlib.contextmanager
def wrap_fmi_calls(wrap):
    """While active, each FMU this process instantiates has every FMI C function ``f`` of its fmpy
    object replaced by ``wrap(instance_name, function_name, f)`` before its first call (fmi2Instantiate
    included), e.g. to time the calls without a profiler (benchmarks/speed_accuracy.py).  The wrapper
    must forward ``argtypes``, ``restype`` and ``argnames``: fmpy's own wrappers read them."""
    _CALL_WRAPPERS.append(wrap)
    try:
        yield
    finally:
        _CALL_WRAPPERS.remove(wrap)


ENUMERATIONS_TOOL = "org.cranefmu.enumerations"   # written by cranefmu.adapter.fmi_adapter (bundled, cannot import this)


def switch_names(md_root) -> dict[str, dict[str, int]]:
    """variable -> {name: code} of the Integer switches an FMU lists in its model description's
    ``VendorAnnotations/Tool name="org.cranefmu.enumerations"`` (none for other FMUs)."""
    out: dict[str, dict[str, int]] = {}
    for tool in md_root.iter("Tool"):
        if tool.get("name") == ENUMERATIONS_TOOL:
            for var in tool.iter("Variable"):
                out[var.get("name")] = {item.get("name"): int(item.get("value")) for item in var.iter("Item")}
    return out


def fmu_switch_names(fmu: Path) -> dict[str, dict[str, int]]:
    """:func:`switch_names` of an .fmu file (its modelDescription.xml read through the guard)."""
    import zipfile

    from .untrusted import check_xml

    with zipfile.ZipFile(fmu) as zf:
        return switch_names(check_xml(zf.read("modelDescription.xml"), f"{Path(fmu).name}/modelDescription.xml"))


NOT_EXTRACTED = ("sources/",)   # FMU folders a run never reads: not unzipped (FMI 2.0 and 3.0 name it so)


def _refused_after_fatal(*args) -> int:
    """An FMI call on an instance that returned fmi2Fatal before: not made, status fatal."""
    return FATAL


class FmuComponent:
    """An instantiated FMI 2.0 co-simulation FMU with name-based access and a log of its messages (an
    FMI 3.0 one through the FMI 2.0 calls of :mod:`.fmi3`)."""

    def __init__(self, name: str, fmu_path: Path, unzipdir: Path):
        self.name = name
        self.unzipdir = Path(unzipdir)
        done = (self.unzipdir / _EXTRACTED).is_file()
        described = _MODEL_DESCRIPTIONS.get(self.unzipdir) if done else None
        if described is None:
            described = self.describe(name, Path(fmu_path), self.unzipdir) if done else \
                self.extract(name, Path(fmu_path), self.unzipdir)
        self.md, self.switches = described
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.fmu = None
        self.alive = False
        self.messages = Messages()   # the FMU's warnings and errors, the last 50 (a new log each instantiation)
        self.can_get_state = bool(self.md.coSimulation.canGetAndSetFMUstate)
        # the values the master reads every step, in one fmi2GetReal (see :meth:`read`)
        self.read_vrs: list[int] = []
        self.fresh = False      # the read buffer holds what the FMU would return now
        self._read = None       # (vr array, count, value array, numpy view of it), built on first read
        self.fatal_listeners: list = []   # called once when the instance returns fmi2Fatal (:meth:`stop_calls`)

    @staticmethod
    def extract(name: str, fmu_path: Path, unzipdir: Path):
        """Unzip ``fmu_path`` safely into ``unzipdir``, check and read its modelDescription.xml, and
        mark the directory done (a later instance from it skips all of this); returns the description
        and the switch names (:func:`switch_names`)."""
        from .untrusted import safe_extract

        # fmpy.extract lets zipfile rewrite '../' entries silently; ours refuses the archive instead.  A run
        # needs modelDescription.xml, binaries/ and resources/: the C sources of a source FMU (sources/, most of
        # a native FMU's files) are checked but not written (measured: 7 ms of CPU an FMU, 2 ms without them)
        try:
            safe_extract(fmu_path, unzipdir, skip=NOT_EXTRACTED)
        except SceneError as err:
            raise SceneError(f"component {name!r}: {err}") from None
        except Exception as err:
            raise SceneError(f"component {name!r}: {fmu_path.name} is not a readable FMU: {err}") from None
        described = FmuComponent.describe(name, fmu_path, unzipdir)
        (unzipdir / _EXTRACTED).touch()
        return described

    @staticmethod
    def describe(name: str, fmu_path: Path, unzipdir: Path):
        """Check and read the modelDescription.xml of the FMU extracted in ``unzipdir`` (by :meth:`extract`, in
        this process or in the one that handed the folder over); returns the description and the switch names."""
        from fmpy import read_model_description

        from .untrusted import check_xml

        try:
            md_xml = (unzipdir / "modelDescription.xml").read_bytes()
        except Exception as err:
            raise SceneError(f"component {name!r}: {fmu_path.name} is not a readable FMU: {err}") from None
        switches = switch_names(check_xml(md_xml, f"component {name!r}: {fmu_path.name}/modelDescription.xml"))
        try:
            md = read_model_description(str(unzipdir), validate=False)
        except Exception as err:
            raise SceneError(f"component {name!r}: {fmu_path.name} is not a readable FMU: {err}") from None
        if md.fmiVersion not in ("2.0", "3.0") or md.coSimulation is None:
            raise SceneError(f"component {name!r}: {fmu_path.name} is not an FMI 2.0 or 3.0 co-simulation FMU "
                             f"(fmiVersion {md.fmiVersion}, co-simulation {'yes' if md.coSimulation else 'no'})")
        if md.fmiVersion == "3.0":
            from .fmi3 import normalize, refuse_unsupported

            refuse_unsupported(md, f"component {name!r}: {fmu_path.name}")
            normalize(md)
        _check_binary(name, fmu_path.name, unzipdir, md.coSimulation.modelIdentifier, md.fmiVersion == "3.0")
        _MODEL_DESCRIPTIONS[unzipdir] = md, switches
        return md, switches

    # --- life cycle ---------------------------------------------------------------------------
    def instantiate(self) -> None:
        if self.md.fmiVersion == "3.0":
            from .fmi3 import slave_class

            cls = slave_class()
        else:
            cls = _slave_class()
        ident = self.md.coSimulation.modelIdentifier
        self._keep = keeps_library(self.md) and not _CALL_WRAPPERS and in_place(self.unzipdir)
        kept = _LOADED.get((str(self.unzipdir), ident)) if self._keep else None
        entry = None
        with contextlib.suppress(IndexError):   # another thread of this process may have taken the last one
            entry = kept.pop() if kept else None
        if entry is not None and self._reset(*entry):
            return
        self.fmu = cls(guid=self.md.guid, unzipDirectory=str(self.unzipdir), modelIdentifier=ident,
                       instanceName=self.name)
        if _CALL_WRAPPERS:
            functions = self.fmu._functions
            for fname, f in list(functions.items()):
                functions[fname] = _CALL_WRAPPERS[-1](self.name, fname, f)
        self.messages = Messages()   # this instance's own (process.instance_callbacks files into it)
        # FMI 3.0 (.fmi3): the instance's log callback files into the log it is handed
        self._callbacks = self.messages if self.md.fmiVersion == "3.0" else _instance_callbacks(self.messages)
        self.fmu.on_fatal = self.stop_calls
        try:
            self.fmu.instantiate(loggingOn=True, callbacks=self._callbacks)
        except Exception as err:
            raise SceneError(f"component {self.name!r} ({self.md.modelName}) could not be instantiated: "
                             f"{self.python_error() or err}") from None
        _hold_pythonfmu_library(self.fmu.dll)
        self._bind()

    def _reset(self, fmu, callbacks, messages) -> bool:
        """Take a kept instance of this FMU (:data:`_LOADED`, same directory hence same instance name) as
        this component's, put back to its start values by fmi2Reset; False (the instance freed) if the FMU
        refuses the reset."""
        messages.clear()   # the log the instance's callbacks file into (process.instance_callbacks)
        try:
            fmu.reset()
        except Exception:
            if not getattr(fmu, "fatal", False):   # after fmi2Fatal no call at all (FMI 2.0)
                with contextlib.suppress(Exception):
                    fmu.fmi2FreeInstance(fmu.component)
            return False
        self.fmu, self._callbacks, self.messages = fmu, callbacks, messages
        self.fmu.fatal = False
        self.fmu.on_fatal = self.stop_calls   # as a fresh instance's: a fatal stops this component's calls
        self._bind()
        return True

    def _bind(self) -> None:
        """The instance is alive: hold what the hot path calls."""
        self.alive = True
        # the hot path calls the C functions themselves (fmpy's wrappers convert lists to new ctypes
        # arrays on every call); argument types as fmpy declared them
        functions = self.fmu._functions
        self._c = self.fmu.component
        self._get_real = functions["fmi2GetReal"]
        self._set_real = functions["fmi2SetReal"]
        self._do_step = functions["fmi2DoStep"]
        self._get_integer = functions["fmi2GetInteger"]
        self._get_boolean = functions["fmi2GetBoolean"]
        self._set_integer = functions["fmi2SetInteger"]
        self._set_boolean = functions["fmi2SetBoolean"]
        self._read = None
        self.fresh = False

    def python_error(self) -> str:
        """The Python exception the FMU's code raised, as pythonfmu logged it (one line), or ''."""
        lines = [line for m in self.messages for line in m.strip().splitlines() if line.strip()]
        errors = [line.strip() for line in lines if _EXCEPTION_LINE.match(line.strip())]
        return errors[-1] if errors else (lines[-1].strip() if lines else "")

    def last_error(self) -> str:
        # the adapter's own message names the cause; pythonfmu's "Fatal py exception" line does not
        own = [m for m in self.messages if not m.startswith("Fatal py exception")]
        return (own or self.messages or ["no message from the FMU"])[-1]

    def free(self) -> None:
        """Terminate and free the instance (every path must end here: pythonfmu corrupts the heap otherwise),
        unless it returned fmi2Fatal, after which FMI 2.0 allows no call at all."""
        if self.fmu is None or not self.alive:
            return
        self.alive = False
        self.fmu.on_fatal = None   # a kept library's fmpy object must not hold this component (and its run)
        if self.fmu.fatal:  # FMI 2.0: after fmi2Fatal no function may be called on the instance
            return
        try:
            self.fmu.terminate()
        except Exception:
            pass
        if getattr(self, "_keep", False):   # terminated, kept alive for the next run's fmi2Reset
            _LOADED.setdefault((str(self.unzipdir), self.md.coSimulation.modelIdentifier), []).append(
                (self.fmu, self._callbacks, self.messages))
            return
        try:
            self.fmu.freeInstance()
        except Exception:
            pass

    # --- variables ------------------------------------------------------------------------------
    def variable(self, name: str, what: str = "variable"):
        try:
            return self.variables[name]
        except KeyError:
            close = [v for v in self.variables if v.lower().startswith(name.lower()[:3])][:6]
            hint = f" (similar: {', '.join(close)})" if close else ""
            raise ParameterSetError(f"{what} {self.name}.{name} does not exist in {self.md.modelName}{hint}") from None

    def vrs(self, names: list[str]) -> list[int]:
        return [self.variable(n).valueReference for n in names]

    def set_start(self, name: str, text: str | float | int | bool) -> None:
        """Set a parameter or start value from text or a number, converted to the variable's type."""
        v = self.variable(name)
        if v.causality not in ("parameter", "input") and v.initial != "exact":
            raise ParameterSetError(f"{self.name}.{name} is a {v.causality} and cannot be set "
                                    f"(only parameters and inputs)")
        where = f"{self.name}.{name}"
        try:
            if v.type == "Real":
                value = float(text)
                self.fmu.setReal([v.valueReference], [value])
            elif v.type in ("Integer", "Enumeration"):
                names = self.switches.get(name, {})
                given = names[text.strip()] if isinstance(text, str) and text.strip() in names else text
                if names and isinstance(given, str):
                    float(given)   # neither a name nor a number: the error lists the names
                declared = v.declaredType
                low = v.min if v.min is not None else getattr(declared, "min", None)
                high = v.max if v.max is not None else getattr(declared, "max", None)
                self.fmu.setInteger([v.valueReference], [fmi_integer(given, where, low, high)])
            elif v.type == "Boolean":
                value = text if isinstance(text, bool) else parse_bool(text)
                self.fmu.setBoolean([v.valueReference], [value])
            else:
                self.fmu.setString([v.valueReference], [str(text)])
        except ParameterSetError:
            raise
        except (ValueError, KeyError, TypeError):
            names = self.switches.get(name)
            allowed = f": allowed {', '.join(f'{n} (= {c})' for n, c in names.items())}" if names else ""
            raise ParameterSetError(f"{where} = {text!r} is not a valid {v.type} value{allowed}") from None
        except Exception as err:
            raise ParameterSetError(f"{where} = {text!r} was refused by the FMU: {self.last_error() or err}") from None
        finally:
            self.fresh = False

    def get_real(self, vrs: list[int]) -> np.ndarray:
        return np.array(self.fmu.getReal(vrs))

    # --- the hot path: preallocated arrays, raw C calls ----------------------------------------------
    def position(self, vrs: list[int]) -> np.ndarray:
        """Where each of ``vrs`` sits in the vector :meth:`read` returns (added to it if new)."""
        out = []
        for vr in vrs:
            if vr not in self.read_vrs:
                self.read_vrs.append(vr)
                self._read = None
            out.append(self.read_vrs.index(vr))
        return np.array(out, dtype=np.intp)

    def read(self) -> np.ndarray:
        """Every value of :attr:`read_vrs` in one fmi2GetReal, or the last read if nothing changed the
        FMU since (:attr:`fresh`).  The array is reused: copy what you keep."""
        if not self.fresh:
            if self._read is None:
                n = len(self.read_vrs)
                values = (ctypes.c_double * n)()
                self._read = ((ctypes.c_uint * n)(*self.read_vrs), n, values, np.ctypeslib.as_array(values))
            vrs, n, values, view = self._read
            status = self._get_real(self._c, vrs, n, values)
            if status > 1:
                self._failed("fmi2GetReal", status)
            self.fresh = True
        return self._read[3]

    def use_buffer(self, values, view: np.ndarray) -> None:
        """Read into ``values`` (a ctypes double array of len(read_vrs), e.g. part of one buffer for
        every component) seen as the numpy array ``view``."""
        n = len(self.read_vrs)
        self._read = ((ctypes.c_uint * n)(*self.read_vrs), n, values, view)
        self.fresh = False

    def write(self, vrs, n: int, values) -> None:
        """fmi2SetReal of the first ``n`` of the ctypes arrays ``vrs``, ``values``.  The caller decides
        whether the inputs set make :attr:`fresh` false (an output depends on them)."""
        status = self._set_real(self._c, vrs, n, values)
        if status > 1:
            self._failed("fmi2SetReal", status)

    def step(self, t: float, h: float) -> None:
        self.fresh = False
        status = self._do_step(self._c, t, h, 1)
        if status > 1:
            self._failed("fmi2DoStep", status)

    def read_discrete(self, vrs, n: int, values, boolean: bool) -> None:
        status = (self._get_boolean if boolean else self._get_integer)(self._c, vrs, n, values)
        if status > 1:
            self._failed("fmi2GetBoolean" if boolean else "fmi2GetInteger", status)

    def write_discrete(self, vrs, n: int, values, boolean: bool) -> None:
        """fmi2SetBoolean (``boolean``) or fmi2SetInteger of the ctypes int arrays ``vrs``, ``values``."""
        status = (self._set_boolean if boolean else self._set_integer)(self._c, vrs, n, values)
        if status > 1:
            self._failed("fmi2SetBoolean" if boolean else "fmi2SetInteger", status)

    def _failed(self, function: str, status: int):
        """Raise what fmpy raises for a status above warning, and remember a fatal one (no call reaches the
        instance after it: :meth:`stop_calls`)."""
        from fmpy.fmi1 import FMICallException

        if status == FATAL:
            if self.fmu.fatal:   # a call :meth:`stop_calls` refused
                raise fatal_instance_error(function)
            self.fmu.mark_fatal()
        raise FMICallException(function=function, status=status)

    def stop_calls(self) -> None:
        """The instance returned fmi2Fatal: the direct calls of the hot path return fmi2Fatal from now on without
        reaching the FMU (pythonfmu released the instance's Python object there: a later call would use freed
        memory, :mod:`.fatal_status`), and :attr:`fatal_listeners` are told (the coupling drops its compiled
        exchange, which holds the C functions themselves)."""
        for name in ("_do_step", "_get_real", "_set_real", "_get_integer", "_get_boolean", "_set_integer",
                     "_set_boolean"):
            setattr(self, name, _refused_after_fatal)
        for listener in self.fatal_listeners:
            listener()
