"""What every study shares: its size, its output folder, the cluster it runs on, the provenance line of
its page, and the record of failed points that makes the command exit non-zero."""
from __future__ import annotations

import csv
import datetime
import os
import platform
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..errors import SettingsError

SIZES = ("smoke", "default", "full")


@dataclass
class Context:
    """One study's run: ``size`` (smoke | default | full), ``output`` folder (tables, figures, page),
    and the Dask cluster (a local one of ``workers`` processes, or ``scheduler``'s), made on first use
    and shared by every study of one command."""

    output: Path
    size: str = "default"
    workers: int | None = None
    scheduler: str | None = None
    say: Callable[[str], None] = print
    prune: bool = False                                   # drop rows of its run tables this study did not use
    failures: list[str] = field(default_factory=list)    # one line per failed point of this study
    ran: int = 0                                          # runs made now
    reused: int = 0                                       # runs of the same request found in the run tables
    made: str = ""                                        # the commit the page names (commit() at the start)
    _used: dict = field(default_factory=dict)             # run table -> the keys this study read
    _client: object = None
    _cluster: object = None

    def __post_init__(self) -> None:
        if self.size not in SIZES:
            raise SettingsError(f"study size = {self.size!r} is not allowed: one of {', '.join(SIZES)}")
        self.output = Path(self.output)
        self.output.mkdir(parents=True, exist_ok=True)
        # taken before the study writes: its own tables and figures in a tracked docs/studies/ would
        # otherwise read as local changes on the page it writes last
        self.made = self.made or commit()

    @property
    def smoke(self) -> bool:
        return self.size == "smoke"

    @property
    def full(self) -> bool:
        return self.size == "full"

    def pick(self, smoke, default, full):
        """The value of this size."""
        return {"smoke": smoke, "default": default, "full": full}[self.size]

    def runs(self, name: str) -> Path:
        """The per-run sweep table ``name`` (resumable) under OUTPUT/runs/<size>/."""
        folder = self.output / "runs" / self.size
        folder.mkdir(parents=True, exist_ok=True)
        return folder / name

    @property
    def client(self):
        if self._client is None:
            from ..sweep.engine import connect

            self._client, self._cluster = connect(self.workers, self.scheduler)
        return self._client

    def note(self, res) -> None:
        """Count a sweep's runs (made now, reused) and remember which rows of its table this study read."""
        self._used.setdefault(Path(res.path), set()).update(r["key"] for r in res.design)
        self.ran += res.ran
        self.reused += res.skipped

    def stale_rows(self) -> tuple[int, bool]:
        """(rows of this study's run tables it did not read: an earlier request, whether they were
        dropped): they are dropped with ``prune``."""
        from ..sweep import table

        stale = 0
        for path, keys in self._used.items():
            old = {r["key"] for r in table.read(path)} - keys
            if old and self.prune:
                table.drop(path, old)
            stale += len(old)
        return stale, self.prune

    def fail(self, text: str) -> None:
        self.failures.append(" ".join(text.split()))

    def close(self) -> None:
        """Close the client and a local cluster, and remove the cluster's scratch folder (in TMPDIR)."""
        if self._client is not None:
            from ..sweep.engine import close

            close(self._client, self._cluster)
            self._client = self._cluster = None


def commit() -> str:
    """The checkout's commit (with "+local changes" when the tracked files differ), else the version."""
    here = Path(__file__).resolve().parent
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=here, capture_output=True, text=True,
                              check=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                               capture_output=True, text=True, check=True, timeout=10).stdout.strip()
        return head + (" +local changes" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        from importlib.metadata import PackageNotFoundError, version

        try:
            return f"cranefmu {version('cranefmu')}"
        except PackageNotFoundError:
            return "unknown"


def check_reproducible(output: str | Path) -> None:
    """Refuse (SettingsError, one line) to write a study into the checkout's docs/ from a tree with
    uncommitted changes: a published page must name a commit that reproduces it (issue 37)."""
    from ..sources import CHECKOUT, IN_CHECKOUT

    if not IN_CHECKOUT:
        return
    docs = (Path(CHECKOUT) / "docs").resolve()
    target = Path(output).resolve()
    if target != docs and docs not in target.parents:
        return
    made = commit()
    if made.endswith("+local changes"):
        raise SettingsError(f"--output {output}: a study is written into docs/ only from a committed tree (the "
                            f"checkout at {made.split()[0]} has uncommitted changes to tracked files): commit "
                            "first, or write elsewhere")


def provenance(command: str, made: str | None = None) -> str:
    """One line saying how a page was made: command, commit (``made``: the one the run started from,
    else the checkout's now), UTC date, machine, load average."""
    load = " / ".join(f"{x:.1f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (f"Generated by `{command}` at commit {made or commit()}, {date}, on {platform.node()} ({os.cpu_count()} "
            f"cores, {platform.machine()}, Python {platform.python_version()}), load average {load} (1/5/15 min) "
            "at the end.")


def write_csv(path: Path, rows: list[dict]) -> Path:
    """``rows`` (dicts with the same keys) as a CSV; floats with repr (read back exactly)."""
    import io

    from ..whole_file import write

    path = Path(path)
    cols = list(dict.fromkeys(k for r in rows for k in r))
    f = io.StringIO(newline="")
    w = csv.writer(f)
    w.writerow(cols)
    for r in rows:
        w.writerow(["" if r.get(c) is None else repr(r[c]) if isinstance(r.get(c), float) else r.get(c)
                    for c in cols])
    write(path, f.getvalue(), "study table")   # whole or the old one: never a half table
    return path


def write_page(ctx: Context, name: str, title: str, lines: list[str]) -> Path:
    """OUTPUT/<name>.md: the title, how it was made, the lines, and the failed points (if any)."""
    cmd = f"cranefmu study {name.replace('_', '-')}" + ("" if ctx.size == "default" else f" --{ctx.size}")
    page = [f"# {title}", "", provenance(cmd, ctx.made), ""]
    if ctx.failures:
        page += [f"**{len(ctx.failures)} failed point(s)** (marked in the table and the figure; the command "
                 "exited 1):", ""] + [f"- {f}" for f in ctx.failures] + [""]
    if ctx._used:
        stale, dropped = ctx.stale_rows()
        page += [f"Runs: {ctx.ran} made now, {ctx.reused} reused from OUTPUT/runs/{ctx.size}/ (a row is reused only "
                 "for the same request: scene file, code, effective settings and inputs)"
                 + (f"; {stale} row(s) of an earlier request {'dropped (--prune)' if dropped else 'kept there, not used (--prune drops them)'}"
                    if stale else "") + ".", ""]
        ctx.say(f"runs: {ctx.ran} now, {ctx.reused} reused" + (f", {stale} stale row(s) "
                f"{'dropped' if dropped else 'kept (--prune drops them)'}" if stale else ""))
    path = ctx.output / f"{name}.md"
    from ..whole_file import write

    write(path, "\n".join(page + lines).rstrip() + "\n", "study page")
    return path


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def finish(fig, ax, path, xlabel: str, ylabel: str, title: str, legend: float = 7, grid: str = "both") -> None:
    """Label ``ax``, grid and legend, and save ``fig`` to ``path`` (PNG, 120 dpi), then free it."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which=grid, alpha=0.3)
    ax.legend(fontsize=legend)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
