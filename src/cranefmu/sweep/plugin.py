"""The scene's .ssp on a remote cluster: a worker plugin writes it on every worker, including one that
joins later (restarted after a crash), and the tasks find it there (:class:`PluginSsp`)."""
from __future__ import annotations

import os
from pathlib import Path

from distributed.diagnostics.plugin import WorkerPlugin

from ..errors import SceneError
from .worker import SspFile


class PluginSsp(SspFile):
    """The scene on a remote cluster: written on each worker by :class:`SspPlugin` at its start."""

    def local(self) -> Path:
        from .worker import _LOCAL

        if self.sha256 not in _LOCAL:
            raise SceneError(f"scene {self.name}: its .ssp ({self.sha256[:16]}) has not reached this worker; "
                             "the sweep's worker plugin did not run here")
        return _LOCAL[self.sha256]


class SspPlugin(WorkerPlugin):
    """Writes the scene's .ssp under each worker's local directory when the worker starts (Dask runs a
    registered worker plugin on every worker, including those that join later)."""

    def __init__(self, ssp: SspFile):
        self.ssp = ssp

    def setup(self, worker) -> None:
        from .worker import _LOCAL

        target = Path(worker.local_directory) / f"cranefmu_{self.ssp.sha256[:16]}" / Path(self.ssp.path).name
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = target.with_suffix(f".{os.getpid()}.part")
        partial.write_bytes(self.ssp.data)
        partial.replace(target)   # atomic: another worker process on the machine never reads half a file
        _LOCAL[self.ssp.sha256] = target

    def teardown(self, worker) -> None:
        pass
