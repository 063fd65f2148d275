"""The per-user build cache: where an installed (or read-only) cranefmu builds its FMUs and .ssp files.

Location: ``$CRANEFMU_CACHE_DIR`` if set, else the platform's user cache folder (platformdirs:
``~/.cache/cranefmu`` on Linux, ``~/Library/Caches/cranefmu`` on macOS,
``%LOCALAPPDATA%\\cranefmu\\Cache`` on Windows).  Inside it, one folder per package version and
source digest (``0.1.0-<16 hex>``), so two versions or two source states never share a file.
Concurrent builds are serialized by an exclusive lock on ``<folder>/.lock``, and every file is
written to a temporary name and renamed into place (see :mod:`cranefmu.build`).
"""
from __future__ import annotations

import contextlib
import os
import re
import shutil
from collections.abc import Iterator
from pathlib import Path

ENV = "CRANEFMU_CACHE_DIR"
_BUILD_FOLDER = re.compile(r"^\d[\w.+!-]*-[0-9a-f]{16}$")  # <version>-<digest>: what versioned_dir makes


def cache_root() -> Path:
    """The cache folder of this user (``$CRANEFMU_CACHE_DIR`` overrides)."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser().resolve()
    from platformdirs import user_cache_path

    return user_cache_path("cranefmu", appauthor=False)


def versioned_dir(digest: str) -> Path:
    """The folder holding the builds of this package version and source digest."""
    from .version import __version__

    return cache_root() / f"{__version__}-{digest[:16]}"


KERNEL_FOLDER = "kernel"   # the compiled exchange kernels (cranefmu.master.kernel), one folder per digest


def clear() -> list[Path]:
    """Remove every build folder (all versions) and the compiled kernels from the cache; returns them.  Only folders named
    as :func:`versioned_dir` names them: a cache root pointed at a folder of other files loses none."""
    root = cache_root()
    removed = sorted(p for p in root.iterdir() if p.is_dir() and (_BUILD_FOLDER.match(p.name) or p.name == KERNEL_FOLDER)
                     ) if root.is_dir() else []
    for folder in removed:
        shutil.rmtree(folder)
    return removed


def writable(folder: Path) -> bool:
    """True if files can be created in ``folder`` (an existing directory)."""
    return folder.is_dir() and os.access(folder, os.W_OK | os.X_OK)


@contextlib.contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder/.lock`` (created with ``folder``) for the block.

    A second process building the same folder waits here, then finds the files built.  On a
    platform without ``fcntl`` (Windows) the block runs unlocked: the atomic renames still keep
    every file whole, at worst two processes build the same file.
    """
    folder.mkdir(parents=True, exist_ok=True)
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    with open(folder / ".lock", "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
