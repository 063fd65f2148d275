"""What a sweep's row depends on beyond its inputs, as one digest that goes into the run's key.

A row is the result of the whole run request, not of its varied inputs alone: the built scene file
(the SSD, its parameter sets, and the FMUs, which carry the physics), the effective run settings and
parameter values the run resolves to (the scene's stored settings and the code's defaults included,
:func:`cranefmu.master.runspec.resolve`), and the code that runs and measures it (the master, the
sweep's worker and metrics, the scenes' metrics).  A change of any of them gives the run another key,
so a resumed sweep or study runs it again instead of reusing a stale row; the rows of the earlier
request stay in the table as rows outside the design (``--prune`` drops them).
"""
from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import asdict
from pathlib import Path

from ..errors import CraneFmuError
from .spec import Run

# the package's code a run's row depends on: everything but the study and command-line front ends
# (what they ask is in the inputs) and the build (what it builds is in the scene file's digest)
_NOT_RUN = ("studies", "cli.py", "build.py", "report")


@functools.lru_cache(maxsize=1)
def code_digest() -> str:
    """SHA-256 (16 hex digits) of the cranefmu package's source the worker runs (.py and .json files)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root)
        if path.suffix not in (".py", ".json") or rel.parts[0] in _NOT_RUN or "__pycache__" in rel.parts:
            continue
        h.update(str(rel.as_posix()).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def effective(ssp: Path, run: Run) -> object:
    """The run's effective settings and parameter values (JSON-able), or the refusal's text: a refused
    request still runs, and fails as its own row on the worker."""
    from ..master.runspec import resolve

    try:
        spec = resolve(ssp, parameters=run.parameters, parameter_set=run.parameter_set,
                       **{"progress": False, **run.settings})
    except CraneFmuError as err:
        return f"refused: {err}"
    settings = {k: repr(v) for k, v in asdict(spec.settings).items() if k != "progress"}
    return [sorted(settings.items()), sorted((f"{c}.{v}", repr(x)) for (c, v), x in spec.overrides.items())]


def digest(ssp: Path, ssp_sha256: str, run: Run) -> str:
    """The request digest of ``run`` on the scene file ``ssp`` (whose content hash is ``ssp_sha256``)."""
    text = json.dumps([ssp_sha256, code_digest(), effective(ssp, run)])
    return hashlib.sha256(text.encode()).hexdigest()[:16]
