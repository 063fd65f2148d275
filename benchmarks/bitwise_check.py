"""Bitwise check of the master: a fixed list of short runs whose results must not change by one bit
when the master's code is reshaped (not a timing; prints a table).

    python benchmarks/bitwise_check.py save DIR       # run every check run, save its arrays and stats
    python benchmarks/bitwise_check.py compare DIR    # run again, compare bit for bit with DIR
    ... --fmus python|native|python,native            # the kind(s) of FMU the runs take (default python)

``--fmus``: each run with the pythonfmu FMUs (key ``scene/mode``; the default, so a baseline saved before
native FMUs existed still compares), the native ones (key ``native/scene/mode``) or both.  With both,
the table also gives each run's largest native-python difference relative to the column's range.

Every run is ``cranefmu.master.run.run(..., isolate=False, progress=False)`` (in-process), each in
a fresh spawned child: pythonfmu FMUs do not survive a second instantiation in one process.  The
comparison is ``np.array_equal`` on every column, equal length, equal ``stats.steps``,
``stats.rejections`` and ``stats.iterations``.
"""
from __future__ import annotations

import json
import multiprocessing
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

SCENES = {"elastic_pendulum": 1.0, "hook_sway": 0.5, "overhead_lift": 0.5, "truck_telescope": 0.3}
MODES = {
    "jacobi_x0": dict(algorithm="jacobi", extrapolation=0, implicit=[]),
    "jacobi_x1": dict(algorithm="jacobi", extrapolation=1, implicit=[]),
    "jacobi_x2": dict(algorithm="jacobi", extrapolation=2, implicit=[]),
    "gauss-seidel_x1": dict(algorithm="gauss-seidel", extrapolation=1),
    "iterative": dict(algorithm="iterative", extrapolation=1),
    "adaptive_extrapolation": dict(algorithm="jacobi", extrapolation=1, adaptive=True, step_control="extrapolation",
                                   implicit=[]),
    "adaptive_ecco": dict(algorithm="jacobi", extrapolation=1, adaptive=True, step_control="ecco", implicit=[]),
}
EXTRA = {"elastic_pendulum/gauss-seidel_x0": dict(algorithm="gauss-seidel", extrapolation=0),
         "overhead_lift/stop_when_lifted": dict(algorithm="jacobi", extrapolation=0, stop_when=["pendulum.lifted"]),
         "overhead_lift/adaptive_stop_when_lifted": dict(algorithm="jacobi", extrapolation=1, adaptive=True,
                                                         stop_when=["pendulum.lifted"]),
         "elastic_pendulum/energy_alarm": dict(algorithm="jacobi", extrapolation=0, energy_alarm=1e-12),
         "hook_sway/no_alarm_x1": dict(algorithm="jacobi", extrapolation=1, instability_alarm=False, implicit=[]),
         "hook_sway/jacobi-plain": dict(algorithm="jacobi-plain", extrapolation=0),
         "truck_telescope/jacobi-plain": dict(algorithm="jacobi-plain", extrapolation=0),
         # the scene's stored implicit group (every bond), at a fine H as every run here
         "truck_telescope/implicit_all": dict(algorithm="jacobi", extrapolation=1, coupling_tolerance=1e-3,
                                              implicit=["foot_heave", "foot_tilt", "tip", "hook", "drum"])}


KINDS = ("python", "native")


def check_runs(kinds: tuple[str, ...] = ("python",)) -> dict[str, tuple[str, dict]]:
    base = {f"{scene}/{mode}": (scene, dict(kw, stop_time=stop, step_size=1e-3))
            for scene, stop in SCENES.items() for mode, kw in MODES.items()}
    for key, kw in EXTRA.items():
        scene = key.partition("/")[0]
        base[key] = (scene, dict(kw, stop_time=SCENES[scene], step_size=1e-3))
    return {("" if kind == "python" else f"{kind}/") + key: (scene, dict(kw, fmus=kind))
            for kind in kinds for key, (scene, kw) in base.items()}


def _one(scene: str, kwargs: dict) -> dict:
    from cranefmu.errors import CraneFmuError
    from cranefmu.master.run import run
    try:
        res = run(scene, isolate=False, progress=False, **kwargs)
    except CraneFmuError as err:
        return {"error": f"{type(err).__name__}: {err}", "result": getattr(err, "result", None)}
    s = res.stats
    return {"result": res.result, "stats": {"steps": s.steps, "rejections": s.rejections,
                                            "iterations": s.iterations, "stopped": s.stopped}}


def execute(kinds: tuple[str, ...] = ("python",)) -> dict[str, dict]:
    ctx = multiprocessing.get_context("spawn")
    out = {}
    for key, (scene, kwargs) in check_runs(kinds).items():
        with ProcessPoolExecutor(1, mp_context=ctx) as pool:
            out[key] = pool.submit(_one, scene, kwargs).result()
    return out


def save(folder: Path, runs: dict[str, dict]) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    meta = {}
    for key, r in runs.items():
        name = key.replace("/", "__")
        if r.get("result") is not None:
            np.save(folder / f"{name}.npy", r["result"])
        meta[key] = {k: v for k, v in r.items() if k != "result"}
    (folder / "stats.json").write_text(json.dumps(meta, indent=1))


def compare(folder: Path, runs: dict[str, dict]) -> bool:
    meta = json.loads((folder / "stats.json").read_text())
    ok_all = True
    print(f"{'run':45s} {'rows':>6s} {'steps':>6s} {'rej':>4s} {'iter':>6s}  result")
    for key, r in runs.items():
        old = meta.get(key)
        path = folder / f"{key.replace('/', '__')}.npy"
        problems = []
        if old is None:
            problems.append("not in the baseline")
        else:
            if old.get("error") != r.get("error"):
                problems.append(f"error {old.get('error')!r} -> {r.get('error')!r}")
            if old.get("stats") != r.get("stats"):
                problems.append(f"stats {old.get('stats')} -> {r.get('stats')}")
            a = np.load(path) if path.exists() else None
            b = r.get("result")
            if (a is None) != (b is None):
                problems.append("result present in one set only")
            elif a is not None:
                if len(a) != len(b) or a.dtype.names != b.dtype.names:
                    problems.append(f"shape {len(a)} x {len(a.dtype.names)} -> {len(b)} x {len(b.dtype.names)}")
                else:
                    bad = [n for n in a.dtype.names if not np.array_equal(a[n], b[n], equal_nan=True)]
                    if bad:
                        problems.append(f"{len(bad)} columns differ: {', '.join(bad[:4])}")
        st = r.get("stats") or {}
        rows = len(r["result"]) if r.get("result") is not None else 0
        verdict = "EQUAL" if not problems else "DIFFERENT: " + "; ".join(problems)
        print(f"{key:45s} {rows:6d} {st.get('steps', '-')!s:>6s} {st.get('rejections', '-')!s:>4s} "
              f"{st.get('iterations', '-')!s:>6s}  {verdict}")
        ok_all = ok_all and not problems
    print("ALL BITWISE EQUAL" if ok_all else "SOME RUNS DIFFER")
    return ok_all


def kinds_agreement(runs: dict[str, dict]) -> None:
    """Each run's largest |native - python| over a column's range (both kinds in ``runs``)."""
    pairs = [(k, f"native/{k}") for k in runs if not k.startswith("native/") and f"native/{k}" in runs]
    if not pairs:
        return
    print(f"\n{'run':45s} {'native vs python, max |diff| / range':>38s}  worst column")
    for py, nat in pairs:
        a, b = runs[py].get("result"), runs[nat].get("result")
        if a is None or b is None or len(a) != len(b):
            print(f"{py:45s} {'-':>38s}  rows {0 if a is None else len(a)} vs {0 if b is None else len(b)}")
            continue
        worst, column = 0.0, ""
        for n in a.dtype.names:
            x, y = np.asarray(a[n], float), np.asarray(b[n], float)
            span = max(float(np.ptp(x)), float(np.max(np.abs(x))) * 1e-12, 1e-300)
            err = float(np.max(np.abs(x - y))) / span
            if err > worst:
                worst, column = err, n
        print(f"{py:45s} {worst:38.3g}  {column}")


def main(argv: list[str]) -> int:
    kinds: tuple[str, ...] = ("python",)
    if "--fmus" in argv:
        at = argv.index("--fmus")
        kinds = tuple(k.strip() for k in argv[at + 1].split(",")) if at + 1 < len(argv) else ()
        argv = argv[:at] + argv[at + 2:]
        if not kinds or any(k not in KINDS for k in kinds):
            print(f"--fmus {','.join(kinds)!r} is not allowed: python, native or python,native")
            return 2
    if len(argv) != 2 or argv[0] not in ("save", "compare"):
        print(__doc__)
        return 2
    folder = Path(argv[1])
    runs = execute(kinds)
    kinds_agreement(runs)
    if argv[0] == "save":
        save(folder, runs)
        for key, r in runs.items():
            print(key, r.get("stats") or r.get("error"))
        return 0
    return 0 if compare(folder, runs) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
