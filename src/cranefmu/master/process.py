"""The process contract of the master, and every piece of process-global state its workarounds keep.

A process that runs FMUs keeps to this contract (pythonfmu and fmpy workarounds); the state they need
lives here, and the modules that use it import it from here:

- **Each run instantiates its pythonfmu (and foreign) FMUs from directories of its own** (:func:`.extracted.fresh_fmu_dirs`);
  a scene of native cranefmu FMUs only instantiates from its extracted directories, and each FMU's instance is kept,
  terminated, for the next run's fmi2Reset (:data:`.fmu._LOADED`, :func:`.extracted.instantiates_in_place`).
  Measured first: a second instantiation from the same extracted directory made the process abort at
  exit ('corrupted double-linked list'). The cause was found later in pythonfmu 0.7.0's binary (its
  ``finalizePythonInterpreter`` writes into its interpreter guard after C++ freed it), and is worked
  around by :func:`.fmu.release_pythonfmu_libraries` from ``atexit`` (issue 23); fresh directories are
  kept because every FMU's bundled code then loads as its own package. All Python FMUs of a process share
  one interpreter (their bundled code has build-unique package names, docs/architecture.md).
- **An .ssp is extracted once per process** (:func:`.extracted.extracted_scene`), keyed by the SHA-256
  of its bytes (a rebuilt scene gets a new one), under :data:`LOCK`, into one temporary directory
  (:data:`ROOT`) removed at exit (``atexit``) or by :func:`clear`; its FMUs are extracted there too, to
  read their model descriptions, but never instantiated from there.  A run's own directories are
  removed in the background (:func:`discard`).
- **The model description of an extracted FMU directory is read once** (:data:`MODEL_DESCRIPTIONS`,
  filled by :class:`.fmu.FmuComponent`; a run's copies adopt it, :func:`adopt_extracted`, and drop it
  when removed, :func:`forget_extracted`).
- **The FMI logger is one function for the life of the process** (:func:`callbacks`): pythonfmu's
  wrapper keeps the logger of an instance in a process-wide place and may call it after that instance
  is gone, so it is never freed.  Each instance gets callbacks of its own (:func:`instance_callbacks`,
  a copy whose ``componentEnvironment`` is the instance's key): the logger files a message into the
  :class:`Messages` of the instance that sent it, which the instance (:class:`.fmu.FmuComponent`)
  owns, so two runs with components of the same name keep separate logs; the key map holds the logs
  weakly (:data:`_LOGS`).  An FMI 3.0 instance's log callback is kept likewise (:data:`FMI3_LOGGERS`).
- **A worker process ends with ``os._exit``** once every FMU is freed (:mod:`.worker`): the
  interpreter's teardown is skipped; an isolated run's worker keeps its extraction cache in the run's
  own temporary directory, which the parent removes whatever happens to the worker.

Process-global state that is no workaround stays with its owner: the scene-name resolver a caller
registers (:mod:`.scene_names`) and the signal handlers, installed only for a run's duration in the
main thread (:mod:`.interrupt`).
"""
from __future__ import annotations

import atexit
import itertools
import queue
import shutil
import tempfile
import threading
import weakref
from pathlib import Path

LOCK = threading.Lock()                 # guards SCENES and ROOT
SCENES: dict[str, tuple[Path, object]] = {}   # .ssp digest -> (its extracted directory, the Scene read)
DIGESTS: dict[tuple[str, int, int], str] = {}   # (path, size, mtime) -> the .ssp's digest
_root: list[Path] = []                  # the one directory of every extracted scene (made on first use)

MODEL_DESCRIPTIONS: dict[Path, tuple[object, dict[str, dict[str, int]]]] = {}   # unzip dir -> (md, switches)
EXTRACTED_MARK = ".cranefmu_extracted"   # written last: the directory holds a whole, checked FMU

class Messages(list):
    """One FMU instance's messages (warning and worse), the last :attr:`KEPT`."""

    KEPT = 50

    def add(self, text: str) -> None:
        self.append(text)
        del self[:-self.KEPT]


_LOGS: "weakref.WeakValueDictionary[int, Messages]" = weakref.WeakValueDictionary()   # key -> its log
_KEYS = itertools.count(1)   # 0 is no key (a NULL componentEnvironment)
IN_PLACE: dict[Path, bool] = {}   # extracted scene directory -> whether its runs instantiate from it (.extracted)
_callbacks: list = []
_INSTANCE_CALLBACKS: list = []   # every instance's own callbacks struct (instance_callbacks), never freed
FMI3_LOGGERS: list = []   # every FMI 3.0 instance's log callback (:mod:`.fmi3`), kept for the same reason


def in_place(unzipdir: Path) -> bool:
    """Whether ``unzipdir`` is an FMU directory of an extracted scene whose runs instantiate from it."""
    return IN_PLACE.get(Path(unzipdir).parent, False)


def scenes_root() -> Path:
    """The directory extracted scenes go to (made, and its removal at exit registered, on first use);
    call under :data:`LOCK`."""
    if not _root or not _root[0].is_dir():
        _root[:] = [Path(tempfile.mkdtemp(prefix="cranefmu_scenes_"))]
        atexit.register(clear)
    return _root[0]


def drop_empty_root() -> None:
    """Remove the scenes' directory if nothing is left in it (after a hand-over); call under :data:`LOCK`."""
    if _root and _root[0].is_dir() and not any(_root[0].iterdir()):
        _root.pop().rmdir()


def clear() -> None:
    """Remove every extracted scene now (they are extracted again when next run)."""
    with LOCK:
        SCENES.clear()
        IN_PLACE.clear()
        if _root:
            shutil.rmtree(_root.pop(), ignore_errors=True)


_TRASH: "queue.Queue[Path]" = queue.Queue()
_remover: list[threading.Thread] = []


def discard(path: Path) -> None:
    """Remove a run's directory in the background (rmdir costs ~2 ms a directory on this machine,
    a third of a warm start-up); whatever is left goes with the cache at exit."""
    _TRASH.put(Path(path))
    if not _remover or not _remover[0].is_alive():
        _remover[:] = [threading.Thread(target=_remove_forever, name="cranefmu-remove", daemon=True)]
        _remover[0].start()


def _remove_forever() -> None:
    while True:
        shutil.rmtree(_TRASH.get(), ignore_errors=True)


def adopt_extracted(src: Path, dst: Path) -> None:
    """``dst`` holds the same checked files as the extracted directory ``src``: reuse its description."""
    if src in MODEL_DESCRIPTIONS:
        MODEL_DESCRIPTIONS[dst] = MODEL_DESCRIPTIONS[src]


def forget_extracted(root: Path) -> None:
    """Drop the descriptions of directories under ``root`` (removed after a run)."""
    for key in [k for k in MODEL_DESCRIPTIONS if root in k.parents]:
        del MODEL_DESCRIPTIONS[key]


def callbacks():
    """The FMI 2.0 callbacks of every instance (fmpy's ``fmi2CallbackFunctions``), made once."""
    if _callbacks:
        return _callbacks[0]
    from ctypes import byref

    from fmpy import calloc, free
    from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                           fmi2CallbackLoggerTYPE)

    def logger(env, instance, status, category, message):
        if status < 2:  # keep warning, discard, error, fatal
            return
        box = _LOGS.get(env or 0)
        if box is not None:   # else: its instance is gone
            box.add(message.decode(errors="replace") if isinstance(message, bytes) else str(message))

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    try:
        from fmpy.logging import addLoggerProxy  # formats printf-style messages

        addLoggerProxy(byref(cb))
    except Exception:
        pass
    _callbacks.append(cb)
    return cb


def instance_callbacks(messages: Messages):
    """FMI 2.0 callbacks for one instance: the process's (:func:`callbacks`) with a
    ``componentEnvironment`` of its own, through which the logger files its messages into
    ``messages``.  The caller keeps the returned struct as long as the instance lives."""
    from ctypes import c_void_p

    base = callbacks()
    key = next(_KEYS)
    _LOGS[key] = messages
    own = type(base).from_buffer_copy(base)   # the same (proxied) logger and memory functions
    own.componentEnvironment = c_void_p(key)
    # kept for the life of the process, as the logger is: an FMU may keep the struct's address (FMI 2.0 lets
    # it use the callbacks until fmi2FreeInstance; pythonfmu's wrapper may log after its instance is gone), and
    # a freed ctypes struct is small-object memory that Python hands to its next objects
    _INSTANCE_CALLBACKS.append(own)
    return own
