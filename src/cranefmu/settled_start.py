"""The settled start as values in the scene file, for hosts that do not settle a scene themselves.

Our master derives the start in initialization mode, iterating until the connections agree
(:mod:`cranefmu.master.initialization`).  Other hosts do less: libcosim 0.11 makes one exchange
sweep per simulator, ecos one pass, fmpy's ``simulate_ssp`` none (docs/interop.md).  So the build
runs our initialization once per parameter set and writes what it settled on as start values of
every connected input ("component.variable" -> value).  Each FMU derives its start state from its
parameters and inputs (docs/equilibrium.md), so with these inputs it computes our start, and an
exchange repeats the same values: the file is a fixed point of the initialization, as loaded.

Our own master ignores these values (a connected input's start value is overwritten by the
initialization anyway; see ``master.run._overrides``), so its results do not depend on them.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Mapping, Sequence

from .errors import CraneFmuError, SceneError
from .master.scene import ConnectionSpec

# one macro step: only the row at t = 0 (after initialization) is used; its length does not matter
_STEP = 1e-3


def settled_inputs(connections: Sequence[ConnectionSpec], first_row: Mapping) -> dict[str, float]:
    """Every connected input's value at t = 0 as our initialization settled it: the source output's
    value in the first row of our run (``first_row[name]``), through the connection's factor and offset."""
    out = {}
    for c in connections:
        source = f"{c.src}.{c.src_var}"
        try:
            value = float(first_row[source])
        except (KeyError, ValueError):
            raise ValueError(f"connection {c}: its source {source!r} is not a recorded column of our run") from None
        out[f"{c.dst}.{c.dst_var}"] = value * c.factor + c.offset
    return out


def settled_starts(ssp: Path, variants: Sequence[tuple[str | None, Mapping | None]]) -> list[dict[str, float]]:
    """For each (parameter set, {"comp.var": value} overrides) of the scene file ``ssp``, the connected
    inputs as our initialization settles them.  Runs in a fresh interpreter (``python -m
    cranefmu.settled_start``, not multiprocessing: a caller's unguarded script is never re-imported):
    the FMUs are instantiated there, never in the caller (a build, an export).  A bad value in an
    override is the child's :class:`CraneFmuError` (its class and message), raised here."""
    request = json.dumps({"ssp": str(ssp), "variants": [[s, dict(p or {})] for s, p in variants]})
    done = subprocess.run([sys.executable, "-m", "cranefmu.settled_start"], input=request, capture_output=True,
                          text=True, env={**os.environ, "PYTHONPATH": _package_parent()})
    try:
        answer = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, ValueError):
        raise SceneError(f"computing the settled start of {Path(ssp).name} failed (exit status {done.returncode}): "
                         f"{done.stderr.strip()[-2000:]}") from None
    if "error" in answer:
        from . import errors

        kind = getattr(errors, answer.get("kind", ""), CraneFmuError)
        raise (kind if isinstance(kind, type) and issubclass(kind, CraneFmuError) else CraneFmuError)(answer["error"])
    return answer["starts"]


def _package_parent() -> str:
    """PYTHONPATH for the child: the folder holding this ``cranefmu`` first (an editable checkout or
    an installed package alike), then the caller's."""
    here = str(Path(__file__).resolve().parents[1])
    return os.pathsep.join([here, *filter(None, [os.environ.get("PYTHONPATH")])])


def main() -> None:
    request = json.loads(sys.stdin.read())
    try:
        starts = _settled_here(request["ssp"], [(s, p) for s, p in request["variants"]])
    except CraneFmuError as err:
        print(json.dumps({"error": str(err), "kind": type(err).__name__}))
        return
    print(json.dumps({"starts": starts}))


def _settled_here(ssp: str, variants: list[tuple[str | None, dict]]) -> list[dict[str, float]]:
    from .master.run import run

    connections = run_scene_connections(ssp)
    out = []
    for parameter_set, parameters in variants:
        result = run(ssp, parameter_set=parameter_set, parameters=parameters or None, stop_time=_STEP,
                     step_size=_STEP, algorithm="jacobi-plain", extrapolation=0, instability_alarm=False).result
        out.append(settled_inputs(connections, result[0]))
    return out


def run_scene_connections(ssp: str) -> list[ConnectionSpec]:
    """The connections of the scene file ``ssp`` (as our master reads them)."""
    from .master.extracted import extracted_scene

    return extracted_scene(Path(ssp))[1].connections


if __name__ == "__main__":
    main()
