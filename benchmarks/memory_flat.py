"""Peak memory of a run with output against its length: ``cranefmu run ... --output FILE`` (which streams its
rows and keeps none, issue 34) for a short and a long run, beside the API with ``keep=True`` (every row in
memory, what the CLI did before) for contrast.

    .venv/bin/python benchmarks/memory_flat.py [--scene elastic_pendulum] [--short 10] [--long 120] [--step 1e-3]

Each case runs in a fresh child process (``python -c``, in-process run); its peak resident set is the
child's ``ru_maxrss`` from ``os.wait4``.  Prints and saves benchmarks/results/memory_flat.md.  Not a test.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"

CLI = ("import sys; from cranefmu import cli; sys.exit(cli.main(['run', {scene!r}, '--stop-time', {stop!r}, "
       "'--step', {step!r}, '--in-process', '--output', {out!r}]))")
API = ("import cranefmu; cranefmu.run({scene!r}, stop_time={stop}, step_size={step}, output={out!r}, keep=True, "
       "progress=False)")


def peak_mib(code: str) -> float:
    """Run ``code`` in a child interpreter; its peak RSS [MiB]."""
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    err = child.stderr.read().decode().strip()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"child failed: {err.splitlines()[-1] if err else status}")
    return usage.ru_maxrss / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="elastic_pendulum")
    ap.add_argument("--short", type=float, default=10.0)
    ap.add_argument("--long", type=float, default=120.0)
    ap.add_argument("--step", type=float, default=1e-3)
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, template in (("cranefmu run --output FILE (streamed)", CLI), ("run(..., keep=True)", API)):
            peaks = []
            for stop in (a.short, a.long):
                out = str(Path(tmp) / f"{stop:g}.csv")
                peaks.append(peak_mib(template.format(scene=a.scene, stop=str(stop) if template is CLI else stop,
                                                      step=str(a.step) if template is CLI else a.step, out=out)))
                Path(out).unlink(missing_ok=True)
            rows.append((label, *peaks))
            print(f"{label}: {peaks[0]:.1f} MiB ({a.short:g} s), {peaks[1]:.1f} MiB ({a.long:g} s)", flush=True)
    n_short, n_long = round(a.short / a.step) + 1, round(a.long / a.step) + 1
    lines = [f"# Peak memory against run length: {a.scene}, H = {a.step:g} s", "",
             f"`python benchmarks/memory_flat.py --scene {a.scene} --short {a.short:g} --long {a.long:g} "
             f"--step {a.step:g}`: peak RSS of a fresh process running the case ({n_short} and {n_long} rows).", "",
             f"| case | {a.short:g} s [MiB] | {a.long:g} s [MiB] | long / short |", "| --- | --- | --- | --- |"]
    lines += [f"| {label} | {s:.1f} | {lg:.1f} | {lg / s:.3f} |" for label, s, lg in rows]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "memory_flat.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
