"""Hand-written SSPs as another tool's user writes them (cofmupy style): components and
connections only, no connectors, no power-bond or settings annotations, parameters in one .ssv."""
from __future__ import annotations

import zipfile
from pathlib import Path

# elastic_pendulum's wiring: the hook's motion to the rope, the rope's force to the hook, and the
# load's rest facts (docs/equilibrium.md)
ROPE_PENDULUM = [("pendulum", v, "rope", f"{v}_hook") for v in ("x", "y", "z", "vx", "vy", "vz")] + \
    [("rope", f"F{a}_hook", "pendulum", f"F{a}_rope") for a in "xyz"] + \
    [("pendulum", "suspended_mass", "rope", "m_load"), ("pendulum", "rest_tension", "rope", "load"),
     ("rope", "hang_length", "pendulum", "drop")]

# elastic_pendulum's default set (ssp/elastic_pendulum/default.ssv), written by hand
ROPE_PENDULUM_PARAMETERS = {"rope.length": 10.0, "rope.E": 1.0e11, "rope.A": 5.655e-5, "rope.n_lines": 1,
                            "rope.zeta": 0.07, "pendulum.dimension": 2, "pendulum.mass": 1000.0,
                            "pendulum.start": 1, "pendulum.theta0": 0.08726646259971647}


def _ssv(parameters: dict) -> str:
    rows = []
    for name, value in parameters.items():
        kind = "Integer" if isinstance(value, int) and not isinstance(value, bool) else "Real"
        rows.append(f'<ssv:Parameter name="{name}"><ssv:{kind} value="{value!r}"/></ssv:Parameter>')
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/'
            'SystemStructureParameterValues" version="1.0" name="parameters"><ssv:Parameters>'
            + "".join(rows) + "</ssv:Parameters></ssv:ParameterSet>")


def write_ssp(dest: Path, components: dict[str, Path], connections: list[tuple[str, str, str, str]],
              parameters: dict | None = None, transform: dict[tuple[str, str], str] | None = None) -> Path:
    """Zip an SSD of ``components`` ({name: .fmu}) and ``connections`` (start element, connector, end
    element, connector) with ``parameters`` bound from resources/parameters.ssv; ``transform`` maps
    (end element, connector) to the inner XML of that connection (e.g. a LinearTransformation)."""
    transform = transform or {}
    elements = "".join(f'<ssd:Component name="{n}" source="resources/{Path(f).name}" '
                       'type="application/x-fmu-sharedlibrary"/>' for n, f in components.items())
    links = []
    for a, av, b, bv in connections:
        inner = transform.get((b, bv))
        attrs = f'startElement="{a}" startConnector="{av}" endElement="{b}" endConnector="{bv}"'
        links.append(f"<ssd:Connection {attrs}>{inner}</ssd:Connection>" if inner else f"<ssd:Connection {attrs}/>")
    binding = '<ssd:ParameterBindings><ssd:ParameterBinding source="resources/parameters.ssv"/></ssd:ParameterBindings>' \
        if parameters else ""
    ssd = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/'
           'SSP1/SystemStructureDescription" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
           f'version="1.0" name="{Path(dest).stem}"><ssd:System name="{Path(dest).stem}">{binding}'
           f'<ssd:Elements>{elements}</ssd:Elements>'
           + (f"<ssd:Connections>{''.join(links)}</ssd:Connections>" if links else "")
           + '</ssd:System><ssd:DefaultExperiment startTime="0" stopTime="1"/></ssd:SystemStructureDescription>')
    with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        if parameters:
            zf.writestr("resources/parameters.ssv", _ssv(parameters))
        for fmu in {Path(f).name: Path(f) for f in components.values()}.values():
            zf.write(fmu, f"resources/{fmu.name}")
    return Path(dest)
