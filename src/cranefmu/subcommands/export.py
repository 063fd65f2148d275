"""``cranefmu export SCENE --output FILE.ssp``: one variant of a scene as a self-contained ``.ssp``
(:mod:`cranefmu.export`, docs/interop.md)."""
from __future__ import annotations

import argparse
import sys

from ..cli_common import parse_set


def add_parser(sub) -> None:
    """Register ``export`` on the subparsers ``sub`` of the cranefmu command."""
    e = sub.add_parser("export", help="write one variant of a scene (a parameter set, --set changes) as a "
                                      "self-contained .ssp with its settled start, for hosts that cannot "
                                      "choose a set (libcosim, ecos, fmpy)")
    e.add_argument("scene", help="scene name under ssp/")
    e.add_argument("--parameter-set", default=None, help="a parameter set of the scene (see cranefmu info); "
                   "default: the default set")
    e.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE",
                   help="change a parameter (repeatable; not a connected input)")
    e.add_argument("--output", required=True, help="the .ssp file to write")
    e.add_argument("--fmus", default=None, choices=("native", "python"), help="the kind of FMU the file holds "
                   "(default: native where built or buildable, else python; cranefmu build)")


def main(args: argparse.Namespace) -> int:
    """Write the variant and say where (on stderr when the archive goes to stdout); returns 0."""
    from ..export import export_scene_kind
    from ..master.output_file import same_file_as

    path, kind = export_scene_kind(args.scene, args.output, args.parameter_set, parse_set(args.set), args.fmus)
    # the archive on standard output (`-`, a link to /proc/self/fd/1): the line goes to stderr
    print(f"wrote {path} (FMUs: {kind or 'neither cranefmu kind'})",
          file=sys.stderr if same_file_as(args.output, 1) else sys.stdout)
    return 0
