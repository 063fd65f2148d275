"""LateSpring (a foreign-style FMU that sets its output only at exitInitializationMode) with the
oscillator's mass, as a hand-written SSP (tests/master/test_foreign_scenes.py, benchmarks/foreign_fmus.py)."""
from __future__ import annotations

import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
IDENTITY = '<ssc:LinearTransformation factor="1" offset="0"/>'


def late_scene(dest: Path, mass_fmu: Path) -> Path:
    """OscMass (``mass_fmu``) held by LateSpring: unitless, so every connection carries an identity
    transformation, as a hand-written SSP of a foreign FMU does.  Builds LateSpring.fmu into ``dest``."""
    from cranefmu.build import build_fmu
    from ..oscillator import SSD

    dest = Path(dest)
    late = dest / "LateSpring.fmu"
    if not late.exists():
        build_fmu(HERE / "LateSpring.py", late)
    ssd = SSD.replace("resources/OscSpring.fmu", "resources/LateSpring.fmu")
    for end in ('endConnector="x_in"', 'endConnector="v_in"', 'endElement="mass" endConnector="F"'):
        ssd = ssd.replace(f"{end}/>", f"{end}>{IDENTITY}</ssd:Connection>")
    ssp = dest / "late.ssp"
    with zipfile.ZipFile(ssp, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        zf.write(mass_fmu, "resources/OscMass.fmu")
        zf.write(late, "resources/LateSpring.fmu")
    return ssp
