"""Our master on scenes and FMUs it did not build (docs/foreign_fmus.md): the numbers that page quotes.

1. A hand-written SSP of our Rope and Pendulum (elastic_pendulum's wiring, no annotations), rope
   E = 1e12 Pa, 10 ms steps, 3 s: without the alarm (rows, rows with the rope slack, peak tension)
   and with it (where the inferred bond stops the run, and its message).
2. The oscillator mass held by LateSpring (cranefmu_support.late), whose force is first set at
   exitInitializationMode: the start position against f / (k_mass + k_spring), the largest |a|,
   the initialization exchanges.
3. SpringSupport (the C test FMU, cranefmu_support.c_fmu) under the Rope and Pendulum: at rest (largest
   deviation of y from -m g / k and of the tension from m g) and released from y = 0 (largest
   difference from the linear two-mass solution, in units of the static sag), jacobi and iterative.
4. elastic_pendulum with the FMI 3.0 builds of Rope and Pendulum against the FMI 2.0 scene: the
   largest difference of any column over 2 s (stored settings).

Every run in a fresh spawned child (pythonfmu FMUs are instantiated once per process).  Writes
benchmarks/results/foreign_fmus.md.

    .venv/bin/python benchmarks/foreign_fmus.py        # about a minute alone
"""
from __future__ import annotations

import multiprocessing
import os
import platform
import sys
import tempfile
import time as clock
import zipfile
from concurrent.futures import ProcessPoolExecutor
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
G = 9.81


def _child(func, *args):
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        return pool.submit(func, *args).result()


def stiff(tmp: str, alarm: bool) -> dict:
    from cranefmu import build as b
    from cranefmu.errors import SimulationError
    from cranefmu.master.run import run
    from cranefmu_support.foreign_ssp import ROPE_PENDULUM, ROPE_PENDULUM_PARAMETERS, write_ssp

    ssp = write_ssp(Path(tmp) / "stiff.ssp", {"rope": b.FMU_DIR / "Rope.fmu", "pendulum": b.FMU_DIR / "Pendulum.fmu"},
                    ROPE_PENDULUM, {**ROPE_PENDULUM_PARAMETERS, "rope.E": 1e12})
    try:
        r = run(ssp, stop_time=3.0, step_size=0.01, progress=False, instability_alarm=alarm).result
        message = ""
    except SimulationError as err:
        r, message = err.result, str(err).split(". Try")[0]
    return {"rows": len(r), "slack": int((r["rope.slack"] > 0).sum()), "peak": float(r["rope.tension"].max()),
            "end": float(r["time"][-1]), "message": message}


def late(tmp: str) -> dict:
    from cranefmu.master.run import run
    from cranefmu_support.late import late_scene
    from cranefmu_support.oscillator import build_oscillator

    osc = build_oscillator(Path(tmp))
    res = run(late_scene(Path(tmp), osc.parent / "OscMass.fmu"), stop_time=0.5, step_size=1e-3, progress=False,
              parameters={"mass.f": G, "mass.k": 40.0, "mass.start": "equilibrium", "spring.k": 100.0})
    r = res.result
    return {"x0": float(r["mass.x"][0]), "expected": G / 140.0, "a": float(abs(r["mass.a"]).max()),
            "exchanges": res.stats.init_iterations}


def c_support(tmp: str) -> dict:
    import numpy as np
    from scipy.linalg import expm

    from cranefmu import build as b
    from cranefmu_support.c_fmu import C_ROPE, K, LOAD, M_SUPPORT, support_scene
    from cranefmu_support.c_fmu.build import build
    from cranefmu.master.run import run

    fmu = build(Path(tmp) / "SpringSupport.fmu")
    out = {}
    rest = support_scene(Path(tmp) / "rest.ssp", b.FMU_DIR, fmu)
    released = support_scene(Path(tmp) / "released.ssp", b.FMU_DIR, fmu, **{"support.start": 0, "rope.zeta": 0.0})
    sag = LOAD * G / K
    a = np.array([[0, 1, 0, 0], [-(K + C_ROPE) / M_SUPPORT, 0, C_ROPE / M_SUPPORT, 0],
                  [0, 0, 0, 1], [C_ROPE / LOAD, 0, -C_ROPE / LOAD, 0]])
    for algorithm in ("jacobi", "iterative"):
        r = run(rest, stop_time=0.2, step_size=1e-3, algorithm=algorithm, progress=False).result
        out[f"rest {algorithm}"] = (float(abs(r["support.y"] + sag).max() / sag),
                                    float(abs(r["rope.tension"] - LOAD * G).max() / (LOAD * G)))
        r = run(released, stop_time=0.2, step_size=1e-4, algorithm=algorithm, extrapolation=1, progress=False).result
        exact = np.array([(expm(a * t) @ [sag, 0.0, sag, 0.0])[0] for t in r["time"]]) - sag
        out[f"released {algorithm}"] = float(abs(r["support.y"] - exact).max() / sag)
    return out


def fmi3(tmp: str) -> dict:
    import numpy as np

    from cranefmu import build as b
    from cranefmu.build import build_fmi3

    src, dst = b.SSP_DIR / "elastic_pendulum.ssp", Path(tmp) / "elastic_pendulum_fmi3.ssp"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for name in zin.namelist():
            data = zin.read(name)
            if name == "SystemStructure.ssd":
                data = data.replace(b"resources/Rope.fmu", b"resources/Rope3.fmu")
                data = data.replace(b"resources/Pendulum.fmu", b"resources/Pendulum3.fmu")
            if not name.endswith(".fmu"):
                zout.writestr(name, data)
        for fmu in ("Rope", "Pendulum"):
            zout.write(build_fmi3(fmu, Path(tmp) / f"{fmu}3.fmu"), f"resources/{fmu}3.fmu")
    runs = [_child(_run_columns, str(p)) for p in (src, dst)]
    return {"columns": len(runs[0]), "max_difference": max(float(np.max(np.abs(np.array(runs[0][k]) -
                                                                               np.array(runs[1][k]))))
                                                           for k in runs[0])}


def _run_columns(ssp: str) -> dict:
    from cranefmu.master.run import run

    r = run(ssp, stop_time=2.0, progress=False).result
    return {k: r[k].tolist() for k in r.dtype.names}


def main() -> None:
    from cranefmu import build as b
    from fmu_floor import commit   # benchmarks/ is the script's folder

    b.build(verbose=False)
    t0 = clock.perf_counter()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="foreign_fmus_") as tmp:
        dirs = [Path(tmp) / n for n in ("off", "on", "late", "c", "fmi3")]
        for d in dirs:
            d.mkdir()
        off, on = _child(stiff, str(dirs[0]), False), _child(stiff, str(dirs[1]), True)
        lt = _child(late, str(dirs[2]))
        c = _child(c_support, str(dirs[3]))
        f3 = fmi3(str(dirs[4]))
    lines = [
        "# Our master on foreign scenes and FMUs (benchmarks/foreign_fmus.py)",
        "",
        f"Commit {commit()}; {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC; Python {platform.python_version()}; "
        f"load average {load:.1f} at the start; {clock.perf_counter() - t0:.0f} s.",
        "",
        "## 1. Hand-written stiff Rope + Pendulum (no annotations), E = 1e12 Pa, H = 10 ms, 3 s",
        "",
        "| alarm | rows | rows with the rope slack | peak tension [kN] | last row [s] |",
        "| --- | --- | --- | --- | --- |",
        f"| off | {off['rows']} | {off['slack']} | {off['peak'] / 1e3:.1f} | {off['end']:.2f} |",
        f"| on (inferred bond) | {on['rows']} | {on['slack']} | {on['peak'] / 1e3:.1f} | {on['end']:.2f} |",
        "",
        f"Static tension {1000 * G / 1e3:.2f} kN. The alarm's message: \"{on['message']}\"",
        "",
        "## 2. LateSpring (force first set at exitInitializationMode) holding the oscillator mass",
        "",
        f"x(0) = {lt['x0']:.12g} m (f / (k_mass + k_spring) = {lt['expected']:.12g} m); largest |a| "
        f"{lt['a']:.3g} m/s2; {lt['exchanges']} initialization exchanges.",
        "",
        "## 3. SpringSupport (C) under the Rope and Pendulum",
        "",
        "| case | jacobi | iterative |",
        "| --- | --- | --- |",
        f"| at rest, 0.2 s, H = 1 ms: max abs(y + m g / k) / (m g / k) | {c['rest jacobi'][0]:.2g} | "
        f"{c['rest iterative'][0]:.2g} |",
        f"| at rest: max abs(T - m g) / (m g) | {c['rest jacobi'][1]:.2g} | {c['rest iterative'][1]:.2g} |",
        f"| released from y = 0, 0.2 s, H = 0.1 ms: max abs(y - linear two-mass) / (m g / k) | "
        f"{c['released jacobi']:.3g} | {c['released iterative']:.3g} |",
        "",
        "## 4. elastic_pendulum, FMI 3.0 builds against FMI 2.0 (stored settings, 2 s)",
        "",
        f"{f3['columns']} columns; largest difference of any value: {f3['max_difference']:.3g}.",
        "",
    ]
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "foreign_fmus.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
