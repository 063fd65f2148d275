"""One writer for every whole file cranefmu writes (export, reports, compose, study pages): the
rules of ``run --output`` (:mod:`cranefmu.master.output_file`) for a file written at once.

- :func:`check` refuses a target before any work: an empty name, an existing directory, a missing
  or unwritable folder, a wrong suffix.  A symbolic link is followed (the file it points to is
  replaced beside it, the link stays a link).
- :func:`write` puts the bytes in a temporary file beside the target (a short name, so a legal
  255-byte target name works), flushes and fsyncs it and renames it into place: a full disk or an
  error leaves the old file or nothing, never a part, and raises one line naming the target.
- Streams are written through, never replaced: ``-`` and ``/dev/stdout`` (standard output),
  ``/dev/fd/N``, and any existing target that is not a regular file or directory (a FIFO, a
  terminal, ``/dev/null``, ``/dev/full``).
"""
from __future__ import annotations

import os
import shutil
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

from .errors import CraneFmuError, SettingsError
from .master.output_file import check_directory, descriptor, is_stream

Content = bytes | str | Callable[[BinaryIO], None]


class WriteError(CraneFmuError):
    """A target could not be written: the message names it, why, and what is left there."""


def check(path: str | Path, what: str, suffixes: tuple[str, ...] = ()) -> Path:
    """The file ``path`` (``what``: the option, for the message) will replace or stream to; refused
    with one line before any work: empty, a directory, a folder that is missing or not writable,
    or (for a file to replace) a suffix not in ``suffixes``."""
    given = str(path)
    if not given.strip():
        raise SettingsError(f"{what} {given!r} is not allowed: an empty name; give a file path")
    if descriptor(given) is not None or is_stream(given):
        _probe_stream(given, what)
        return Path(given)
    target = Path(os.path.realpath(given)) if os.path.islink(given) else Path(given)
    if target.is_dir():
        raise SettingsError(f"{what} {given!r} is not allowed: it is an existing directory; give a file path")
    if suffixes and target.suffix.lower() not in suffixes and Path(given).suffix.lower() not in suffixes:
        raise SettingsError(f"{what} {given!r} is not allowed: give a file name ending in "
                            f"{' or '.join(suffixes)}")
    check_directory(target.parent, what, given)
    return target


def _probe_stream(given: str, what: str) -> None:
    """A write of no bytes to a descriptor or a device, which fails where the whole write would for
    want of room (``/dev/full``) or a closed or read-only descriptor; a FIFO is not opened (that waits
    for its reader)."""
    number = descriptor(given)
    try:
        if number is not None:
            os.write(number, b"")
            return
        if not stat.S_ISCHR(os.stat(given).st_mode):
            return
        fd = os.open(given, os.O_WRONLY | os.O_NONBLOCK)
        try:
            os.write(fd, b"")
        finally:
            os.close(fd)
    except OSError as err:
        raise SettingsError(f"{what} {given!r} is not allowed: it cannot be written ({err.strerror})") from None


def write(path: str | Path, content: Content, what: str = "output") -> Path:
    """Write ``content`` (bytes, text as UTF-8, or a function writing into a binary file) to ``path``
    whole or not at all (see the module).  Returns the path given.  Raises :class:`WriteError`."""
    given = str(path)
    target = check(given, what)
    number = descriptor(given)
    if number is not None or is_stream(given):
        try:
            fd = os.dup(number) if number is not None else os.open(given, os.O_WRONLY)
        except OSError as err:
            raise WriteError(f"{what} {given!r} could not be opened: {err.strerror}") from None
        try:
            with os.fdopen(fd, "wb", closefd=True) as f:
                _put(f, content)
        except OSError as err:
            raise WriteError(f"{what} {given!r} was not written: {err.strerror} (a stream: what it took is "
                             "there)") from None
        return Path(given)
    existed = target.exists()
    try:
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=".cranefmu-", suffix=".tmp")
    except OSError as err:
        raise WriteError(f"{what} {given!r} was not written: no temporary file in {target.parent} "
                         f"({err.strerror})") from None
    try:
        with os.fdopen(fd, "wb") as f:
            _put(f, content)
            f.flush()
            os.fsync(f.fileno())
            mode = stat.S_IMODE(os.stat(target).st_mode) if existed else 0o666 & ~_umask()
            os.fchmod(f.fileno(), mode)
        os.replace(tmp, target)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        kept = "the old file is kept" if existed else "nothing was written"
        raise WriteError(f"{what} {given!r} was not written: {err.strerror}; {kept}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return Path(given)


def copy(source: Path, path: str | Path, what: str = "output") -> Path:
    """Write the file ``source`` (e.g. one built in a temporary folder) to ``path`` with :func:`write`."""
    def put(f: BinaryIO) -> None:
        with open(source, "rb") as src:
            shutil.copyfileobj(src, f, 1 << 20)
    return write(path, put, what)


def _put(f: BinaryIO, content: Content) -> None:
    if isinstance(content, str):
        f.write(content.encode("utf-8"))
    elif isinstance(content, (bytes, bytearray)):
        f.write(content)
    else:
        content(f)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
