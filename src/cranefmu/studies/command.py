"""``cranefmu study NAME``: run a published study into ``--output DIR`` (tables, figures, page)."""
from __future__ import annotations

import argparse
import sys
import time as clock

from . import STUDIES, module
from .common import Context


def run_studies(names: list[str], output: str, size: str, workers: int | None = None,
                scheduler: str | None = None, say=print, prune: bool = False) -> dict[str, list[str]]:
    """Run the studies ``names`` (sharing one cluster) into ``output``; {name: its failed points}.
    ``prune``: drop the rows of their run tables that they did not read (an earlier request)."""
    failures: dict[str, list[str]] = {}
    shared = ctx = Context(output, size, workers, scheduler, say)   # its commit is taken before any study writes
    try:
        for name in names:
            ctx = Context(output, size, workers, scheduler, say, prune, made=shared.made)
            ctx._client, ctx._cluster = shared._client, shared._cluster
            t0 = clock.perf_counter()
            module(name).run(ctx)
            shared._client, shared._cluster = ctx._client, ctx._cluster
            failures[name] = ctx.failures
            say(f"study {name} ({size}): {len(ctx.failures)} failed point(s), {clock.perf_counter() - t0:.0f} s; "
                f"wrote {ctx.output / (STUDIES[name] + '.md')}")
    finally:   # also when a study is interrupted before it handed back the cluster it started
        shared._client, shared._cluster = shared._client or ctx._client, shared._cluster or ctx._cluster
        shared.close()
    return failures


def main(args: argparse.Namespace) -> int:
    names = list(STUDIES) if args.name == "all" else [args.name]
    from ..sweep.engine import interrupt_once

    size = "smoke" if args.smoke else "full" if args.full else "default"
    from .common import check_reproducible

    check_reproducible(args.output)
    interrupt_once()
    try:
        failures = run_studies(names, args.output, size, args.workers, args.scheduler, prune=args.prune)
    except KeyboardInterrupt as err:
        import signal

        from ..master.interrupt import signal_name

        signum = getattr(err, "signum", signal.SIGINT)   # SIGTERM, SIGHUP: the CLI's handler
        by = "" if signum == signal.SIGINT else f" by {signal_name(signum)}"
        print(f"cranefmu: study interrupted{by}; finished runs are kept under {args.output}/runs/{size}/, the same "
              "command resumes", file=sys.stderr)
        return 128 + signum
    bad = {k: v for k, v in failures.items() if v}
    if bad:
        for name, lines in bad.items():
            print(f"study {name}: {len(lines)} failed point(s); first: {lines[0]}", file=sys.stderr)
        return 1
    return 0


def add_parser(sub) -> None:
    """Register ``study`` on the subparsers ``sub`` of the cranefmu command."""
    s = sub.add_parser("study", help="run a published study (tables, figures and its page into --output); "
                                     "exits 1 if a point failed")
    s.add_argument("name", choices=(*STUDIES, "all"), help="the study, or all of them (one shared cluster)")
    size = s.add_mutually_exclusive_group()
    size.add_argument("--smoke", action="store_true", help="a small grid through every code path (CI)")
    size.add_argument("--full", action="store_true", help="the full grid (docs/studies/)")
    s.add_argument("--output", default="studies", metavar="DIR", help="folder for the tables, figures and pages "
                   "(default ./studies; the docs' are in docs/studies)")
    s.add_argument("--workers", type=int, default=None, help="worker processes of the local cluster "
                   "(default: the cores)")
    s.add_argument("--scheduler", default=None, metavar="ADDRESS", help="use the Dask cluster at this address")
    s.add_argument("--prune", action="store_true", help="drop the rows of OUTPUT/runs/SIZE/ the study did not "
                   "use (an earlier request: other settings, scene build or code); without it they are kept and "
                   "the page counts them")
