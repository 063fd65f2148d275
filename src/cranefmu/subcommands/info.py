"""``cranefmu info SCENE``: what a scene contains, the settings it stores and the exchange a run takes."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import CraneFmuError


def add_parser(sub) -> None:
    """Register ``info`` on the subparsers ``sub`` of the cranefmu command."""
    from ..master.settings import add_arguments

    i = sub.add_parser("info", help="components, parameter sets, parameters and connections of a scene")
    i.add_argument("scene")
    add_arguments(i, ("fmus",))   # which kind's scene file it describes (the FMUs' descriptions differ)


def main(args: argparse.Namespace) -> int:
    """Print the scene's description, then the exchange lines (a probe run); returns 0."""
    from ..fmu_kinds import info_line
    from ..master.extracted import extracted_scene
    from ..master.run import resolve_scene
    from ..scenes.info import describe

    ssp = resolve_scene(args.scene, getattr(args, "fmus", None))
    workdir, scene = extracted_scene(ssp)   # the guarded extract a run uses
    print("\n".join([*describe(scene), info_line(args.scene, ssp, workdir, scene)]), flush=True)
    print("\n".join(_exchange_lines(ssp, scene)))
    return 0


def _exchange_lines(ssp: Path, scene) -> list[str]:
    """``info``'s lines on the exchange a run at the stored settings takes (compiled kernel or Python, and
    why), from a probe run of a few steps: the scene's settings, and each parameter set storing its own."""
    from ..exchange_probe import probe

    lines = ["  exchange at the stored settings (a probe run of the first steps; cranefmu run says it for every run):"]
    for name in [None, *[n for n in scene.parameter_sets if scene.set_settings.get(n)]]:
        try:
            steps, label = probe(ssp, parameter_set=name)
            lines.append(f"    {name or 'default'} ({steps} steps): {label}")
        except CraneFmuError as err:   # a set whose run fails at once: said here, the description stands
            lines.append(f"    {name or 'default'}: the probe run failed: {err}")
    return lines
