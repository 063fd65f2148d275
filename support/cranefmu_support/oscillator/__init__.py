"""The master's test problem: a linear two-mass oscillator split into two FMUs (the master tests and
benchmarks/energy_drift.py, foreign_fmus.py use it).

``OscMass`` (mass 1 on spring k1 to the ground) gets the coupling force F; ``OscSpring`` (the
coupling spring kc and mass 2 on spring k2) gets the position and velocity of mass 1 and returns
F: a force/displacement coupling with direct feedthrough in OscSpring.  :mod:`.exact` holds
the monolithic solution (matrix exponential).
"""
from __future__ import annotations

import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="oscillator">
  <ssd:System name="oscillator">
    <ssd:Elements>
      <ssd:Component name="mass" source="resources/OscMass.fmu" type="application/x-fmu-sharedlibrary"/>
      <ssd:Component name="spring" source="resources/OscSpring.fmu" type="application/x-fmu-sharedlibrary"/>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="mass" startConnector="x" endElement="spring" endConnector="x_in"/>
      <ssd:Connection startElement="mass" startConnector="v" endElement="spring" endConnector="v_in"/>
      <ssd:Connection startElement="spring" startConnector="F" endElement="mass" endConnector="F"/>
    </ssd:Connections>
    <ssd:Annotations>
      <ssc:Annotation type="org.cranefmu.powerbonds">
        <cf:PowerBonds xmlns:cf="urn:org.cranefmu.powerbonds">
          <cf:Bond name="coupling">
            <cf:Side component="spring" force="F" velocity="v_in"/>
            <cf:Side component="mass" force="F" velocity="v"/>
          </cf:Bond>
        </cf:PowerBonds>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="1"/>
</ssd:SystemStructureDescription>
"""


def build_oscillator(dest: Path, ssd: str = SSD, name: str = "oscillator", resources: dict | None = None) -> Path:
    """Build OscMass.fmu and OscSpring.fmu into ``dest`` (once) and zip them with ``ssd`` and
    ``resources`` ({file name: text}, e.g. parameter sets); returns the .ssp."""
    from cranefmu.build import build_fmu

    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    fmus = []
    for stem in ("OscMass", "OscSpring"):
        fmu = dest / f"{stem}.fmu"
        if not fmu.exists():
            build_fmu(HERE / f"{stem}.py", fmu)
        fmus.append(fmu)
    ssp = dest / f"{name}.ssp"
    with zipfile.ZipFile(ssp, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        for fmu in fmus:
            zf.write(fmu, f"resources/{fmu.name}")
        for fname, text in (resources or {}).items():
            zf.writestr(f"resources/{fname}", text)
    return ssp
