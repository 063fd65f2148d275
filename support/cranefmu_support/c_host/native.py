"""Build and run the C host (host.c) on a scene's FMUs; used by tests/fmu/test_native_hosts.py and
benchmarks/native_host_cost.py.

pythonfmu's linux64 binary embeds CPython but does not link libpython (it leaves the symbols
unresolved), so a C host must put libpython into the process first (``LD_PRELOAD``), and the
embedded interpreter must find numpy/scipy: the environment's ``bin`` first on ``PATH`` (CPython
derives its prefix, and so a venv's site-packages, from the ``python3`` it finds there) and, to be
safe, its site-packages on ``PYTHONPATH``.
"""
from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
import sysconfig
from graphlib import TopologicalSorter
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "host.c"


def fmi2_headers() -> Path:
    """The FMI 2.0 headers shipped with fmpy (fmpy/c-code/fmi2Functions.h)."""
    import fmpy

    return Path(fmpy.__file__).parent / "c-code"


def compiler() -> str | None:
    return shutil.which(os.environ.get("CC", "gcc")) or shutil.which("cc")


def compile_host(out_dir: Path) -> Path:
    """Compile host.c into ``out_dir/host``; raises RuntimeError with the compiler's message."""
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (gcc or cc) on PATH")
    exe = Path(out_dir) / "host"
    cmd = [cc, "-O2", "-std=c11", "-Wall", "-I", str(fmi2_headers()), str(SOURCE), "-o", str(exe), "-ldl"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"compiling {SOURCE.name} failed: {done.stderr.strip()}")
    return exe


def libpython() -> Path:
    """The shared libpython of this interpreter (what a C host must preload)."""
    libdir = sysconfig.get_config_var("LIBDIR")
    name = sysconfig.get_config_var("LDLIBRARY")
    path = Path(libdir) / name
    if not path.exists() or not name.endswith(".so") and ".so." not in name:
        raise RuntimeError(f"this Python has no shared libpython ({path}); pythonfmu FMUs need one")
    return path


def host_environment(base: dict[str, str] | None = None) -> dict[str, str]:
    """Environment for a C host running pythonfmu FMUs with this interpreter's packages."""
    env = dict(os.environ if base is None else base)
    env["LD_PRELOAD"] = str(libpython())
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = os.pathsep.join(site.getsitepackages())
    return env


def write_config(path: Path, fmus: list[tuple[str, Path]], starts: dict[str, object],
                 connections: list[tuple[str, str, str, str]], outputs: list[tuple[str, str]],
                 start_time: float, stop_time: float, step: float, hold_gil: bool = False) -> list[str]:
    """Write a host config for FMUs ``[(instance name, unzip dir)]``.

    starts: {"comp.var": value}; connections: (src, src_var, dst, dst_var); outputs: (comp, var).
    Connections are written in the order a feedthrough source must be read after its own inputs were
    set (the order cranefmu's master uses).  Returns the CSV column names.
    """
    from fmpy import read_model_description

    index = {name: i for i, (name, _) in enumerate(fmus)}
    mds = {name: read_model_description(str(d)) for name, d in fmus}
    var = {name: {v.name: v for v in md.modelVariables} for name, md in mds.items()}
    lines = []
    for name, d in fmus:
        md = mds[name]
        lines.append(f"fmu {name} {Path(d).resolve()} {md.coSimulation.modelIdentifier} {md.guid}")
    for key, value in starts.items():
        comp, _, vname = key.partition(".")
        v = var[comp][vname]
        kind = {"Real": "real", "Integer": "int"}.get(v.type)
        if kind is None:
            raise ValueError(f"start value {key}: type {v.type} is not supported by the C host")
        lines.append(f"{kind} {index[comp]} {v.valueReference} {float(value)!r}")
    # destination order: a component whose inputs come from a feedthrough output goes after its source
    feeds = {name: {u.variable.name for u in md.outputs if u.dependencies}
             for name, md in mds.items()}
    graph: dict[str, set[str]] = {name: set() for name in index}
    for src, sv, dst, _ in connections:
        if sv in feeds[src]:
            graph[dst].add(src)
    order = list(TopologicalSorter(graph).static_order())
    for dst in order:
        for src, sv, d, dv in connections:
            if d == dst:
                lines.append(f"conn {index[src]} {var[src][sv].valueReference} {index[d]} {var[d][dv].valueReference}")
    columns = []
    for comp, vname in outputs:
        lines.append(f"out {index[comp]} {var[comp][vname].valueReference} {comp}.{vname}")
        columns.append(f"{comp}.{vname}")
    lines.append(f"run {start_time!r} {stop_time!r} {step!r}")
    if hold_gil:
        lines.append("hold_gil 1")
    Path(path).write_text("\n".join(lines) + "\n")
    return columns


def run_host(exe: Path, config: Path, csv: Path, timeout: float = 300.0) -> tuple[dict[str, float], str]:
    """Run the host; returns ({"steps", "seconds_per_step", "freed"}, stderr).  Raises on failure."""
    done = subprocess.run([str(exe), str(config), str(csv)], capture_output=True, text=True,
                          env=host_environment(), timeout=timeout)
    if done.returncode != 0:
        raise RuntimeError(f"C host exited with {done.returncode}: {done.stderr.strip()[-2000:]}")
    info: dict[str, float] = {}
    for line in done.stdout.splitlines():
        words = line.split()
        if words[:1] == ["steps"]:
            info["steps"] = int(words[1])
            info["seconds_per_step"] = float(words[3])
        elif words[:1] == ["freed"]:
            info["freed"] = int(words[1])
    return info, done.stderr
