"""``cranefmu compose SOURCE --output X.ssp``: a scene source anywhere on disk (a scene.toml, its
folder, or any ``<name>.toml``) composed and built into an .ssp that ``cranefmu run X.ssp`` runs.

The shipped scenes (``ssp/<scene>/scene.toml``) need no command: ``cranefmu build`` writes their SSDs.
"""
from __future__ import annotations

import argparse
import shutil
import tempfile
import zipfile
from pathlib import Path

from . import compose, read_source


def pack(source: Path, dest: Path) -> Path:
    """Compose ``source`` and write the .ssp ``dest``: its SSD, the .ssv files beside the source and the
    FMUs.  When every FMU is one cranefmu builds, through the build (each set's settled start, the
    component bindings libcosim reads); with a foreign FMU, a plain archive our master settles itself."""
    from .. import build as b

    src = read_source(source)
    ours = sorted({c.fmu for c in src.components if not c.fmu.endswith(".fmu")})
    if ours:
        b.build(verbose=False, only=ours)
    folder = src.path.parent
    composed = compose(source, b.FMU_DIR)
    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cranefmu_compose_") as tmp:
        staged = Path(tmp) / composed.source.name
        staged.mkdir()
        (staged / "SystemStructure.ssd").write_bytes(composed.ssd)
        for ssv in sorted(folder.glob("*.ssv")):
            shutil.copy2(ssv, staged / ssv.name)
        fmus = {iface.fmu for iface in composed.interfaces.values()}
        if all(f.parent == b.FMU_DIR for f in fmus):
            return b.build_ssp(staged, dest)
        with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr("SystemStructure.ssd", composed.ssd)
            for ssv in sorted(staged.glob("*.ssv")):
                zf.write(ssv, f"resources/{ssv.name}")
            for fmu in sorted(fmus):
                zf.write(fmu, f"resources/{fmu.name}")
    return dest


def write_osp(source: Path, folder: Path) -> Path:
    """Compose ``source`` into ``folder`` as libcosim's other scene form: ``OspSystemStructure.xml``
    (whole ports joined as variable groups, :func:`.osp.osp_system_structure`), its FMUs and their
    ``<Model>_OspModelDescription.xml``.  The default set are the initial values, the stored step
    (else 1 ms) the base step."""
    from .. import build as b
    from ..master.scene import read_ssd
    from .osp import osp_file_name, osp_model_description, osp_system_structure

    src = read_source(source)
    ours = sorted({c.fmu for c in src.components if not c.fmu.endswith(".fmu")})
    if ours:
        b.build(verbose=False, only=ours)
    composed = compose(source, b.FMU_DIR)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cranefmu_compose_") as tmp:
        (Path(tmp) / "SystemStructure.ssd").write_bytes(composed.ssd)
        for ssv in sorted(src.path.parent.glob("*.ssv")):
            shutil.copy2(ssv, Path(tmp) / ssv.name)
        scene = read_ssd(Path(tmp) / "SystemStructure.ssd", Path(tmp), b.FMU_DIR)
    for iface in composed.interfaces.values():
        shutil.copy2(iface.fmu, folder / iface.fmu.name)
        if iface.ports:
            (folder / osp_file_name(iface)).write_bytes(osp_model_description(iface))
    target = folder / "OspSystemStructure.xml"
    target.write_bytes(osp_system_structure(composed, scene.bound, float(scene.settings.get("step_size", 1e-3))))
    return target


def add_parser(sub) -> None:
    """Register ``compose`` on the subparsers ``sub`` of the cranefmu command."""
    c = sub.add_parser("compose", help="compose a scene source (scene.toml: components, ports, connect lines) "
                                       "into an .ssp that cranefmu run takes (docs/composition.md)")
    c.add_argument("source", help="a scene source: a .toml file, or a folder holding scene.toml")
    c.add_argument("--output", default=None, help="the .ssp to write (default: <scene name>.ssp here)")
    c.add_argument("--ssd", default=None, metavar="FILE", help="also write the generated SystemStructure.ssd here")
    c.add_argument("--osp", default=None, metavar="DIR", help="also write the scene for libcosim's OSP loader: "
                   "DIR/OspSystemStructure.xml (ports joined as variable groups), the FMUs and their "
                   "<Model>_OspModelDescription.xml")
    c.set_defaults(func=_cmd_compose)


def _cmd_compose(args: argparse.Namespace) -> int:
    from .. import build as b

    src = read_source(Path(args.source))
    path = pack(Path(args.source), Path(args.output or f"{src.name}.ssp"))
    if args.ssd:
        Path(args.ssd).write_bytes(compose(args.source, b.FMU_DIR).ssd)
    if args.osp:
        print(f"wrote {write_osp(Path(args.source), Path(args.osp))}")
    print(f"wrote {path} (scene {src.name}: {len(src.components)} components)")
    return 0
