"""Round trip of the composed scenes: every parameter set of every shipped scene run from its
hand-written SSD (commit 0cc7c7f, the last before ssp/<scene>/scene.toml; truck_slewing's: 85f4244) and
from the generated one, compared bit for bit (not a timing).

    python benchmarks/compose_roundtrip.py [STOP_TIME]

Each run (iterative coupling, extrapolation 1, H = 1 ms, to STOP_TIME = 0.05 s: the mode in which
another order of the connections differs in the last bits) in a fresh spawned child, as
bitwise_check.py does.  Prints and writes benchmarks/results/compose_roundtrip.md.
"""
from __future__ import annotations

import multiprocessing
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from result_table import ROOT, save, stamp

HAND_WRITTEN = "0cc7c7f"
LATER = {"truck_slewing": "85f4244"}   # scenes composed later: the last commit of their hand-written SSD


def _run(ssp: str, parameter_set: str | None, stop_time: float):
    from cranefmu.master.run import run

    return run(ssp, parameter_set=parameter_set, stop_time=stop_time, step_size=1e-3, algorithm="iterative",
               extrapolation=1).result


def _hand_written_ssp(scene: str, tmp: Path) -> Path:
    from cranefmu import build as b

    folder = tmp / scene
    folder.mkdir()
    commit = LATER.get(scene, HAND_WRITTEN)
    text = subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:ssp/{scene}/SystemStructure.ssd"],
                          capture_output=True, text=True, check=True).stdout
    (folder / "SystemStructure.ssd").write_text(text)
    for ssv in (b.SSP_SOURCES / scene).glob("*.ssv"):
        shutil.copy2(ssv, folder / ssv.name)
    return b.build_ssp(folder, tmp / f"{scene}_hand_written.ssp")


def main(stop_time: float) -> int:
    from cranefmu import build as b
    from cranefmu.compose import has_source
    from cranefmu.master.scene import read_scene_folder

    t0 = time.time()
    b.build(verbose=False)
    ctx = multiprocessing.get_context("spawn")
    rows, same = [], True
    with tempfile.TemporaryDirectory() as tmp:
        for folder in [d for d in b.scene_dirs() if has_source(d)]:
            scene = folder.name
            old = _hand_written_ssp(scene, Path(tmp))
            for pset in [None, *read_scene_folder(folder, b.FMU_DIR).sets]:
                results = []
                for ssp in (old, b.SSP_DIR / f"{scene}.ssp"):
                    with ProcessPoolExecutor(1, mp_context=ctx) as pool:
                        results.append(pool.submit(_run, str(ssp), pset, stop_time).result())
                a, c = results
                equal = a.dtype.names == c.dtype.names and len(a) == len(c) and all(
                    np.array_equal(a[n], c[n], equal_nan=True) for n in a.dtype.names)
                same &= equal
                rows.append(f"| {scene} | {pset or 'default'} | {len(a)} | {len(a.dtype.names)} | "
                            f"{'bitwise equal' if equal else 'DIFFERENT'} |")
    save("compose_roundtrip", [
        "# Composed scenes against the hand-written SSDs", "", stamp("compose_roundtrip.py"), "",
        f"Every parameter set, iterative coupling (extrapolation 1), H = 1 ms, {stop_time:g} s: the SSD of "
        f"commit {HAND_WRITTEN} (" + ", ".join(f"{k}: {v}" for k, v in LATER.items()) + ") against the one "
        "generated from scene.toml.", "",
        "| scene | parameter set | rows | columns | result |", "| --- | --- | ---: | ---: | --- |", *rows, "",
        "All bitwise equal." if same else "SOME DIFFER."], t0)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main(float(sys.argv[1]) if len(sys.argv) > 1 else 0.05))
