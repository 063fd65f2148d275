"""truck_slewing with and without the chassis foot's power bonds: what declaring them changes.

The composed scene (ssp/truck_slewing/scene.toml) joins the boom foot O2 to the chassis as ports with
'no bond', as the hand-written SSD (commit 85f4244) had it; without 'no bond' the port lines declare three
power bonds: foot_heave (Fy_base with vy_base), foot_pitch (Mz_base with the pitch rate) and foot_roll
(Mx_base with the roll rate).  Each run below runs on the three SSDs (hand-written, composed as committed,
composed with the foot bonds declared: same parameters, same settings) and on the monolith; the table
gives each run's end (the stop condition or alarm, the rows), the scene's metrics, whether the columns it
shares with the hand-written run are bitwise equal, and the largest relative difference of the metrics
from the monolith.

    nice -n 10 .venv/bin/python benchmarks/truck_slewing_bonds.py        (writes results/truck_slewing_bonds.md)
    .venv/bin/python benchmarks/truck_slewing_bonds.py --smoke           (1 s runs into truck_slewing_bonds_smoke.md)
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from result_table import ROOT, save, stamp

HAND_WRITTEN = "85f4244"   # the last commit whose truck_slewing SSD was written by hand
KEYS = ("max_sway_deg", "N_min", "N_max", "tipping_time")

# (label, parameters, settings): the stored settings, coarser explicit steps (the hook bond goes unstable
# from about 50 ms), the adaptive ECCO control (it steers by the bonds' energy residuals), a load that tips
# during the slew, and every declared bond solved implicitly ("all": the hand-written SSD's hook, tip and
# drum; the composed one's also the three foot bonds)
ALL = {"hand-written": ["hook", "tip", "drum"], "composed": ["hook", "tip", "drum"],
       "foot bonds declared": ["hook", "tip", "drum", "foot_heave", "foot_pitch", "foot_roll"]}
RUNS = [
    ("stored settings (jacobi x1, H = 10 ms)", {}, {}),
    ("jacobi x1, H = 20 ms", {}, {"step_size": 0.02}),
    ("jacobi x1, H = 40 ms", {}, {"step_size": 0.04}),
    ("adaptive, ECCO, tolerance 1e-3", {}, {"adaptive": True, "step_control": "ecco", "tolerance": 1e-3}),
    ("every declared bond implicit, H = 50 ms", {}, {"step_size": 0.05, "implicit": "all"}),
    ("every declared bond implicit, H = 100 ms", {}, {"step_size": 0.1, "implicit": "all"}),
    ("7 t (over the side: 6097 kg), stored settings", {"pendulum.mass": 7000.0}, {}),
    ("7 t, jacobi x1, H = 20 ms", {"pendulum.mass": 7000.0}, {"step_size": 0.02}),
    ("7 t, stored settings, no instability alarm", {"pendulum.mass": 7000.0}, {"instability_alarm": False}),
]


def hand_written_ssp(tmp: Path) -> Path:
    from cranefmu import build as b

    folder = tmp / "truck_slewing"
    folder.mkdir()
    text = subprocess.run(["git", "-C", str(ROOT), "show", f"{HAND_WRITTEN}:ssp/truck_slewing/SystemStructure.ssd"],
                          capture_output=True, text=True, check=True).stdout
    (folder / "SystemStructure.ssd").write_text(text)
    for ssv in (b.SSP_SOURCES / "truck_slewing").glob("*.ssv"):
        shutil.copy2(ssv, folder / ssv.name)
    return b.build_ssp(folder, tmp / "truck_slewing_hand_written.ssp")


def _for(ssd: str, settings: dict) -> dict:
    return {**settings, "implicit": ALL[ssd]} if settings.get("implicit") == "all" else settings


def declared_ssp(tmp: Path) -> Path:
    """The composed scene with its foot ports' 'no bond' deleted: the three foot bonds declared."""
    from cranefmu import build as b
    from cranefmu.compose import compose

    folder = tmp / "declared" / "truck_slewing"
    shutil.copytree(b.SSP_SOURCES / "truck_slewing", folder)
    source = folder / "scene.toml"
    source.write_text(source.read_text().replace(" no bond\"", "\""))
    composed = compose(folder, b.FMU_DIR)
    assert {"foot_heave", "foot_pitch", "foot_roll"} <= {bond.name for bond in composed.expanded.bonds}
    (folder / "SystemStructure.ssd").write_bytes(composed.ssd)
    return b.build_ssp(folder, tmp / "truck_slewing_declared.ssp")


def one(ssp: Path, parameters: dict, settings: dict, stop: float):
    """(result rows, how the run ended)."""
    from cranefmu.errors import CraneFmuError, SimulationError
    from cranefmu.master.run import run

    try:
        r = run(ssp, stop_time=stop, parameters=parameters, progress=False, **settings)
        return r.result, (r.stats.stopped or f"ran to {stop:g} s")
    except SimulationError as err:
        return err.result, "FAILED: " + " ".join(str(err).split())[:160]
    except CraneFmuError as err:
        return None, "refused: " + " ".join(str(err).split())[:160]


def _off(x: float, ref: float) -> float:
    """Relative difference (absolute against 0; a tipping time on one side only: inf)."""
    if math.isnan(x) or math.isnan(ref):
        return 0.0 if math.isnan(x) and math.isnan(ref) else math.inf
    return abs(x - ref) / abs(ref) if ref else abs(x - ref)


def cells(rows, end: str, mono: dict | None) -> str:
    from cranefmu.scenes import metrics

    if rows is None or not len(rows):
        return f"{end} | - | - | - | - | - |"
    m = metrics("truck_slewing", rows)
    err = "-"
    if mono is not None:
        err = f"{max(_off(m[k], mono[k]) for k in KEYS):.2g}"
    return f"{end} ({len(rows)} rows) | " + " | ".join(f"{m[k]:.6g}" for k in KEYS) + f" | {err} |"


def main(stop: float, result: str) -> int:
    from cranefmu import build as b
    from cranefmu.analysis.reference import solve
    from cranefmu.scenes import metrics

    t0 = time.time()
    b.build(verbose=False)
    lines = [f"# truck_slewing: the chassis foot's power bonds declared or not, {stop:g} s",
             "", stamp("truck_slewing_bonds.py"), "",
             f"Hand-written: the SSD of commit {HAND_WRITTEN} (no foot bonds); composed: ssp/truck_slewing/scene.toml "
             "as committed (the foot joined with 'no bond'); foot bonds declared: the same without 'no bond' "
             "(bonds foot_heave, foot_pitch, foot_roll). 'shared columns': the columns a result shares with the "
             "hand-written one, compared bit for bit (declared bonds add bond.foot_*.E and .dE). 'vs monolith': "
             "largest relative difference of the four metrics from the monolith's (Radau, rtol 1e-7; a tipping "
             "time on one side only: inf; the monolith has no stop condition and runs on after tipping).", "",
             "| run | SSD | end | " + " | ".join(KEYS) + " | vs monolith |", "| --- " * (4 + len(KEYS)) + "|"]
    monos = {}
    with tempfile.TemporaryDirectory() as tmp:
        ssps = {"hand-written": hand_written_ssp(Path(tmp)), "composed": b.SSP_DIR / "truck_slewing.ssp",
                "foot bonds declared": declared_ssp(Path(tmp))}
        for label, parameters, settings in RUNS:
            key = tuple(sorted(parameters.items()))
            if key not in monos:
                ref = solve("truck_slewing", stop, np.linspace(0.0, stop, int(round(200 * stop)) + 1),
                            parameters=parameters, rtol=1e-7)
                monos[key] = metrics("truck_slewing", ref)
                lines.append(f"| {label.split(',')[0] if parameters else 'default set'} | monolith | ran to {stop:g} s | "
                             + " | ".join(f"{monos[key][k]:.6g}" for k in KEYS) + " | 0 |")
                print(lines[-1], flush=True)
            first = None
            for ssd, ssp in ssps.items():
                got, end = one(ssp, parameters, _for(ssd, settings), stop)
                same = ""
                if first is None:
                    first = got
                elif got is not None and first is not None and len(got) and len(first):
                    shared = [n for n in first.dtype.names if n in got.dtype.names]
                    same = " (shared columns: " + ("bitwise equal" if len(first) == len(got) and all(
                        np.array_equal(first[n], got[n], equal_nan=True) for n in shared) else "DIFFERENT") + ")"
                lines.append(f"| {label} | {ssd}{same} | {cells(got, end, monos[key])}")
                print(lines[-1], flush=True)
    save(result, lines, t0)
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:
        sys.exit(main(1.0, "truck_slewing_bonds_smoke"))
    sys.exit(main(30.0, "truck_slewing_bonds"))
