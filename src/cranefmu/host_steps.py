"""The largest plain-Jacobi step at which a scene stays stable: the step a host that runs plain Jacobi
(libcosim 0.11, ecos) can use, where the scene's stored step is for our own coupling (extrapolation,
re-read feedthrough outputs) and may blow up there (overhead_lift at its stored 2 ms:
tests/tools/test_hosts_as_loaded.py).

Measured per scene and parameter set by ``benchmarks/jacobi_stable_step.py`` (our ``jacobi-plain``, which
equals libcosim's run to 3e-12; stable = the run ends without the instability alarm) into the scene
folder's ``host_steps.json`` (``ssp/<scene>/host_steps.json``, a source of the scene's .ssp).  The build writes it into every .ssp it makes (:func:`annotate`): the System's
``org.cranefmu.hosts`` annotation (every set's step, the span it was measured over and the stored step)
and, for the file's bound set, libcosim's own ``osp:FixedStepAlgorithm baseStepSize`` in the
DefaultExperiment, which ``CosimExecution.from_ssp_file(path)`` (no step given) runs with.
``cranefmu info`` shows it (:func:`read`).
"""
from __future__ import annotations

import json

from .master.host_steps import ANNOTATION, CF_NS, read  # noqa: F401 - the reader is the master's (a scene file's part)
from .sources import SSP_SOURCES

FILE = "host_steps.json"   # in each scene folder, written by benchmarks/jacobi_stable_step.py
OSP_ANNOTATION = "com.opensimulationplatform"          # libcosim's ssp_parser reads it (prefix "osp:" literally)
OSP_NS = "http://opensimulationplatform.com/SSP/OSPAnnotations"


def measured(scene: str) -> dict[str, dict]:
    """Set name -> {"step": [s], "span": [s], "stored_step": [s]} of scene ``scene``: the sets whose
    stable step was found on the ladder; {} for a scene not measured."""
    store = SSP_SOURCES / scene / FILE
    if not store.is_file():
        return {}
    sets = json.loads(store.read_text())
    order = sorted(sets, key=lambda name: (name != "default", name))   # the default set first
    return {name: {k: sets[name][k] for k in ("step", "span", "stored_step")} for name in order
            if sets[name].get("step")}


def annotate(root, steps: dict[str, dict]) -> None:
    """Add ``steps`` (set name -> {"step", "span", "stored_step"}) to the SSD ``root`` (lxml, in place):
    the System's ``org.cranefmu.hosts`` annotation, and the "default" set's step as libcosim's fixed-step
    base step (the set the file binds).  Nothing for an empty ``steps``."""
    from lxml import etree

    from .master.scene import SSC_NS, SSD_NS

    if not steps:
        return
    system = root.find(f"{{{SSD_NS}}}System")
    holder = system.find(f"{{{SSD_NS}}}Annotations")
    if holder is None:
        holder = etree.SubElement(system, f"{{{SSD_NS}}}Annotations")
    ann = etree.SubElement(holder, f"{{{SSC_NS}}}Annotation", type=ANNOTATION)
    table = etree.SubElement(ann, f"{{{CF_NS}}}PlainJacobiSteps", nsmap={"cf": CF_NS})
    for name, m in steps.items():
        etree.SubElement(table, f"{{{CF_NS}}}ParameterSet", name=name, step=repr(float(m["step"])),
                         span=repr(float(m["span"])), stored_step=repr(float(m["stored_step"])))
    if "default" not in steps:
        return
    experiment = root.find(f"{{{SSD_NS}}}DefaultExperiment")
    if experiment is None:
        experiment = etree.Element(f"{{{SSD_NS}}}DefaultExperiment")
        system.addnext(experiment)
    annotations = experiment.find(f"{{{SSD_NS}}}Annotations")
    if annotations is None:
        annotations = etree.SubElement(experiment, f"{{{SSD_NS}}}Annotations")
    osp = etree.SubElement(annotations, f"{{{SSC_NS}}}Annotation", type=OSP_ANNOTATION)
    algorithm = etree.SubElement(osp, f"{{{OSP_NS}}}Algorithm", nsmap={"osp": OSP_NS})
    etree.SubElement(algorithm, f"{{{OSP_NS}}}FixedStepAlgorithm", baseStepSize=repr(float(steps["default"]["step"])))
    # "osp" declared on the root: libcosim iterates osp:Algorithm's children and takes an xmlns attribute
    # there for an algorithm ("Unknown algorithm: <xmlattr>")
    etree.cleanup_namespaces(root, top_nsmap={"osp": OSP_NS})


def info_lines(steps: dict[str, dict], stored_now: dict[str, float] | None = None) -> list[str]:
    """``cranefmu info`` lines for the steps a file carries.  ``stored_now``: set name -> the scene's stored
    step [s] today; where it is not the step stored when the plain-Jacobi step was measured (the
    annotation's ``stored_step``), the line names both."""
    if not steps:
        return ["  plain-Jacobi step for other hosts (libcosim, ecos): not measured for this file"]
    lines = ["  largest plain-Jacobi step at which the scene stays stable (use it in libcosim or ecos, which run "
             "plain Jacobi; measured by benchmarks/jacobi_stable_step.py, docs/interop.md):"]
    for name, m in steps.items():
        then, now = m["stored_step"], (stored_now or {}).get(name)
        if now is None or now == then:
            stored = f"stored step {then * 1e3:g} ms"
        else:
            stored = f"measured when the stored step was {then * 1e3:g} ms; stored step now {now * 1e3:g} ms"
        lines.append(f"    {name}: {m['step'] * 1e3:g} ms ({stored}; stable over {m['span']:g} s)")
    return lines
