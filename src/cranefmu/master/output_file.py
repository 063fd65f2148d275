"""Where a run's CSV goes: checked before the run, written beside the target, renamed into place at the end.

A regular target ``out.csv`` is written as ``out.csv.part`` (same directory, so the final rename is
atomic) and locked with ``flock`` for the run: a failed start leaves an existing ``out.csv`` byte for
byte as it was, and a second run on the same target refuses instead of interleaving.  A target that
is not a regular file (``/dev/stdout``, a FIFO, ``/dev/full``) is written directly.
"""
from __future__ import annotations

import errno
import fcntl
import os
import tempfile
from pathlib import Path

from ..errors import SettingsError

REFUSED_SUFFIXES = (".ssp", ".fmu")


def check_target(path: str | Path, what: str = "output", scene: Path | None = None) -> Path:
    """Refuse a target the run could not write or should not overwrite, before the run starts."""
    path = Path(path)
    if path.suffix.lower() in REFUSED_SUFFIXES or (scene is not None and path.resolve() == Path(scene).resolve()):
        raise SettingsError(f"{what} = {str(path)!r} is not allowed: it names a scene or FMU file; give a .csv path")
    if path.is_dir():
        raise SettingsError(f"{what} = {str(path)!r} is not allowed: it is a directory; give a file path in it")
    if path.exists() and not path.is_file():
        return path  # a device or FIFO: written directly
    check_directory(path.parent, what, str(path))
    return path


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

    @classmethod
    def claim(cls, target: str | Path, scene: Path | None = None) -> "OutputFile":
        target = check_target(target, scene=scene)
        if target.exists() and not target.is_file():
            try:
                return cls(target, None, os.open(target, os.O_WRONLY))
            except OSError as err:
                raise SettingsError(f"output = {str(target)!r} is not allowed: cannot open it ({err.strerror})") from None
        part = target.with_name(target.name + ".part")
        while True:
            fd = os.open(part, os.O_RDWR | os.O_CREAT, 0o644)
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

    def is_ours(self) -> bool:
        """The .part file on disk is still the one this claim locked (not renamed, not another run's)."""
        try:
            return self.part is not None and os.stat(self.part).st_ino == os.fstat(self.fd).st_ino
        except (FileNotFoundError, OSError):
            return False

    def salvage(self) -> int:
        """After a writer died: cut a torn last line so the CSV is well-formed; returns the data rows."""
        if not self.is_ours():
            return 0
        size = os.fstat(self.fd).st_size
        with open(self.part, "rb") as f:
            data = f.read()
        end = data.rfind(b"\n") + 1
        if end < size:
            os.ftruncate(self.fd, end)
        return max(0, data[:end].count(b"\n") - 1)

    def finish(self, rows: int) -> Path | None:
        """Rename the part into place if it holds a row, else remove it; returns where the rows are."""
        if self.part is None:
            return self.target if rows else None
        if not self.is_ours():
            return self.target if rows else None   # finished by the process that wrote it
        if rows > 0:
            os.replace(self.part, self.target)
            return self.target
        self.part.unlink(missing_ok=True)
        return None

    def release(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1
