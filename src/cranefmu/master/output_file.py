"""Where a run's CSV goes: checked before the run, written beside the target, renamed into place at the end.

A regular target ``out.csv`` is written as ``out.csv.part`` (same directory, so the final rename is
atomic) and locked with ``flock`` for the run: a failed start leaves an existing ``out.csv`` byte for
byte as it was, and a second run on the same target refuses instead of interleaving.  A symbolic
link is followed first: the rows replace the file it points to, beside that file, and the link
stays a link.  A stream is written directly, never renamed: ``-`` and ``/dev/stdout`` (standard
output), ``/dev/stderr``, ``/dev/fd/N``, and any existing target that is not a regular file (a
terminal, a FIFO, ``/dev/null``).  A target that cannot be replaced at the end (made immutable, or
a directory now) keeps its rows in ``out.csv.part`` and the run fails with one line naming both.
"""
from __future__ import annotations

import errno
import fcntl
import os
import re
import stat
import tempfile
from pathlib import Path

from ..errors import SettingsError, SimulationError

REFUSED_SUFFIXES = (".ssp", ".fmu")
PART_SUFFIX = ".part"
_DESCRIPTOR_PATH = re.compile(r"^/(?:dev/fd|proc/self/fd)/(\d+)$")
_NAMED_DESCRIPTORS = {"-": 1, "/dev/stdout": 1, "/dev/stderr": 2}


def descriptor(path: str | Path) -> int | None:
    """The open file descriptor ``path`` names (``-``, ``/dev/stdout``, ``/dev/fd/3``), else None."""
    text = str(path)
    if text in _NAMED_DESCRIPTORS:
        return _NAMED_DESCRIPTORS[text]
    found = _DESCRIPTOR_PATH.match(text)
    return int(found.group(1)) if found else None


def is_stream(path: str | Path) -> bool:
    """Rows for ``path`` are streamed to it directly: a descriptor name, or an existing non-regular file."""
    if descriptor(path) is not None:
        return True
    try:
        mode = os.stat(path).st_mode   # follows links: /dev/tty, a FIFO, /dev/null
    except OSError:
        return False
    return not stat.S_ISREG(mode) and not stat.S_ISDIR(mode)


def same_file_as(path: str | Path, fd: int) -> bool:
    """``path`` is where descriptor ``fd`` writes (``--output /dev/stdout`` or ``-`` with fd 1)."""
    if descriptor(path) == fd:
        return True
    try:
        return os.path.samestat(os.stat(path), os.fstat(fd))
    except OSError:
        return False


def check_target(path: str | Path, what: str = "output", scene: Path | None = None) -> Path:
    """Refuse a target the run could not write or should not overwrite, before the run starts;
    returns the path the rows will replace (a symbolic link's target) or the stream as given."""
    given = str(path)
    if descriptor(given) is not None or is_stream(given):
        return Path(given)
    path = Path(given)
    real = Path(os.path.realpath(path))
    if os.path.realpath(os.path.abspath(path)) != os.path.abspath(path):   # a link on the way: its target
        path = real
    if {Path(given).suffix.lower(), real.suffix.lower()} & set(REFUSED_SUFFIXES) \
            or (scene is not None and real == Path(scene).resolve()):
        raise SettingsError(f"{what} = {given!r} is not allowed: it names a scene or FMU file; give a .csv path")
    if path.is_dir():
        raise SettingsError(f"{what} = {given!r} is not allowed: it is a directory; give a file path in it")
    check_directory(path.parent, what, given)
    longest = _name_max(path.parent) - len(PART_SUFFIX)
    if len(path.name.encode()) > longest:
        raise SettingsError(f"{what} = {given!r} is not allowed: its file name is {len(path.name.encode())} bytes, "
                            f"at most {longest} (the file system's limit less {PART_SUFFIX!r})")
    return path


def _name_max(directory: Path) -> int:
    try:
        return os.pathconf(directory if str(directory) else ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def check_directory(directory: Path, what: str, given: str) -> None:
    """The directory exists and a file can be created in it (probed: permissions, read-only mounts)."""
    directory = Path(directory) if str(directory) else Path(".")
    if not directory.is_dir():
        raise SettingsError(f"{what} = {given!r} is not allowed: directory {directory} does not exist")
    try:
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError as err:
        raise SettingsError(f"{what} = {given!r} is not allowed: directory {directory} is not writable "
                            f"({err.strerror})") from None


class OutputFile:
    """The claim on one CSV target for one run: ``fd`` is where rows go; :meth:`finish` puts them in place."""

    def __init__(self, target: Path, part: Path | None, fd: int):
        self.target = Path(target)
        self.part = part        # None: the target is written directly
        self.fd = fd
        self.problem = ""       # why the rows could not be put in place (they stay in ``part``)

    @classmethod
    def claim(cls, target: str | Path, scene: Path | None = None) -> "OutputFile":
        given = str(target)
        target = check_target(target, scene=scene)
        number = descriptor(given)
        if number is not None or is_stream(given):
            try:   # a descriptor is shared, not reopened: a shell's `>>` keeps appending
                fd = os.dup(number) if number is not None else os.open(given, os.O_WRONLY)
            except OSError as err:
                raise SettingsError(f"output = {given!r} is not allowed: cannot open it ({err.strerror})") from None
            return cls(target, None, fd)
        part = target.with_name(target.name + PART_SUFFIX)
        while True:
            try:
                fd = os.open(part, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as err:
                raise SettingsError(f"output = {given!r} is not allowed: cannot create {part} "
                                    f"({err.strerror})") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as err:
                os.close(fd)
                if err.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                    raise SettingsError(f"output = {str(target)!r} is not allowed now: another run is writing it "
                                        f"(into {part}); wait for it or choose another --output") from None
                raise
            try:   # the path may have been renamed into place by the run that held it: claim a fresh file
                same = os.stat(part).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                os.ftruncate(fd, 0)
                return cls(target, part, fd)
            os.close(fd)

    def _holds(self, path: Path | None) -> bool:
        try:
            return path is not None and self.fd >= 0 and os.stat(path).st_ino == os.fstat(self.fd).st_ino
        except OSError:
            return False

    def is_ours(self) -> bool:
        """The .part file on disk is still the one this claim locked (not renamed, not another run's)."""
        return self.part is not None and self._holds(self.part)

    def salvage(self) -> int:
        """After a writer died: cut a torn last line so the CSV is well-formed; returns the data rows
        (also when the writer had already renamed the file into place)."""
        path = self.part if self.is_ours() else self.target if self.part is not None and self._holds(self.target) \
            else None
        if path is None:
            return 0
        size = os.fstat(self.fd).st_size
        with open(path, "rb") as f:
            data = f.read()
        end = data.rfind(b"\n") + 1
        if end < size:
            os.ftruncate(self.fd, end)
        return max(0, data[:end].count(b"\n") - 1)

    def finish(self, rows: int) -> Path | None:
        """Rename the part into place if it holds a row, else remove it; returns where the rows are.
        A failed rename leaves them in the part (:attr:`problem` says why); see :meth:`check_placed`."""
        if self.part is None:
            return self.target if rows else None
        if not self.is_ours():
            return self.target if rows else None   # finished by the process that wrote it
        if rows > 0:
            try:
                os.replace(self.part, self.target)
            except OSError as err:
                self.problem = (f"output {str(self.target)!r} cannot be replaced ({err.strerror}): the {rows} rows "
                                f"are kept in {self.part}")
                return self.part
            return self.target
        self.part.unlink(missing_ok=True)
        return None

    def check_placed(self, result=None) -> None:
        """Raise :class:`SimulationError` (with ``result``) if :meth:`finish` could not put the rows in place."""
        if self.problem:
            raise SimulationError(self.problem, result, self.part)

    def abandon(self) -> None:
        """When a run ends without finishing its file (an early interrupt): whole rows go in place,
        an empty part is removed."""
        if self.is_ours():
            self.finish(self.salvage())

    def release(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1
