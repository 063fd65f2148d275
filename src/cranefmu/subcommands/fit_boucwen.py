"""``cranefmu fit-boucwen LOOP.csv``: the nine modified Bouc-Wen rope parameters fitted to a measured
load-unload loop (:mod:`cranefmu.analysis.fit_boucwen`)."""
from __future__ import annotations

import argparse


def add_parser(sub) -> None:
    """Register ``fit-boucwen`` on the subparsers ``sub`` of the cranefmu command."""
    from ..analysis.fit_boucwen import add_arguments

    f = sub.add_parser("fit-boucwen", help="fit the nine modified Bouc-Wen rope parameters (seed 001 eq. 1-3) "
                                           "to a measured load-unload loop CSV (elongation, force)")
    add_arguments(f)


def main(args: argparse.Namespace) -> int:
    """Fit and print (and write) the parameters; 0, 1 if the fit did not converge, 2 on bad input."""
    from ..analysis.fit_boucwen import run

    return run(args)
