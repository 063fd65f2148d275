"""``cranefmu compose SOURCE --output X.ssp``: a scene source anywhere on disk (a scene.toml, its
folder, or any ``<name>.toml``) composed and built into an .ssp that ``cranefmu run X.ssp`` runs.

The shipped scenes (``ssp/<scene>/scene.toml``) need no command: ``cranefmu build`` writes their SSDs.
"""
from __future__ import annotations

import argparse
import shutil
import tempfile
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from . import Composed, compose, read_source


def built(source: Path) -> Composed:
    """``source`` composed, the FMUs cranefmu builds (``fmu = "Rope"``) built first."""
    from .. import build as b

    ours = sorted({c.fmu for c in read_source(source).components if not c.fmu.endswith(".fmu")})
    if ours:
        b.build(verbose=False, only=ours)
    return compose(source, b.FMU_DIR)


@contextmanager
def staged(composed: Composed) -> Iterator[Path]:
    """A temporary scene folder: the generated SSD and the .ssv files beside the source."""
    with tempfile.TemporaryDirectory(prefix="cranefmu_compose_") as tmp:
        folder = Path(tmp) / composed.source.name
        folder.mkdir()
        (folder / "SystemStructure.ssd").write_bytes(composed.ssd)
        for ssv in sorted(composed.source.path.parent.glob("*.ssv")):
            shutil.copy2(ssv, folder / ssv.name)
        yield folder


def pack(source: Path | Composed, dest: Path) -> Path:
    """Write the .ssp ``dest`` of ``source`` (a scene source, or one composed): its SSD, the .ssv files
    beside the source and the FMUs.  When every FMU is one cranefmu builds, through the build (each
    set's settled start, the component bindings libcosim reads); with a foreign FMU, a plain archive
    our master settles itself."""
    from .. import build as b

    from .. import whole_file

    composed = source if isinstance(source, Composed) else built(source)
    whole_file.check(dest, "--output", (".ssp",))
    fmus = sorted({iface.fmu for iface in composed.interfaces.values()})
    with staged(composed) as folder:
        packed = folder.parent / f"{composed.source.name}.ssp"
        if all(f.parent == b.FMU_DIR for f in fmus):
            b.build_ssp(folder, packed, host_steps=_shipped_host_steps(composed))
        else:
            with zipfile.ZipFile(packed, "w", zipfile.ZIP_DEFLATED) as zf:
                for f in sorted(folder.iterdir()):
                    zf.write(f, f.name if f.suffix == ".ssd" else f"resources/{f.name}")
                for fmu in fmus:
                    zf.write(fmu, f"resources/{fmu.name}")
        return whole_file.copy(packed, dest, "--output")   # beside the target, renamed: whole or nothing


def write_osp(source: Path | Composed, folder: Path, ssp: Path | None = None) -> Path:
    """Write ``source`` into ``folder`` as libcosim's other scene form: ``OspSystemStructure.xml``
    (whole ports joined as variable groups, :func:`.osp.osp_system_structure`), its FMUs and their
    ``<Model>_OspModelDescription.xml``.  The initial values are the default set and its settled start
    (every connected input as our initialization settles it, :mod:`cranefmu.settled_start`, computed
    from ``ssp``, the scene packed, or a pack made here), so libcosim starts the scene at rest as the
    .ssp does.  The base step is the stored step (else 1 ms), but not above the measured stable
    plain-Jacobi step of a shipped scene (:mod:`cranefmu.host_steps`): libcosim runs plain Jacobi."""
    import tempfile

    from .. import build as b
    from ..master.scene import Parameter, read_scene_folder
    from ..settled_start import settled_starts
    from .. import whole_file
    from .osp import osp_file_name, osp_model_description, osp_system_structure

    composed = source if isinstance(source, Composed) else built(source)
    with staged(composed) as scene_dir:
        scene = read_scene_folder(scene_dir, b.FMU_DIR)
    with tempfile.TemporaryDirectory(prefix="cranefmu_osp_") as tmp:
        given = ssp is not None and Path(ssp).is_file()   # not a stream the .ssp was written through
        packed = Path(ssp) if given else pack(composed, Path(tmp) / f"{composed.source.name}.ssp")
        start = settled_starts(packed, [(None, None)])[0]
    values = {**scene.bound, **{k: Parameter(k, "Real", v) for k, v in start.items()}}
    step = float(scene.settings.get("step_size", 1e-3))
    stable = _shipped_host_step(composed)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for iface in composed.interfaces.values():
        shutil.copy2(iface.fmu, folder / iface.fmu.name)
        if iface.ports:
            (folder / osp_file_name(iface)).write_bytes(osp_model_description(iface))
    target = folder / "OspSystemStructure.xml"
    return whole_file.write(target, osp_system_structure(composed, values, min(step, stable or step)), "--osp")


def _shipped_host_steps(composed: Composed) -> dict[str, dict]:
    """The measured stable plain-Jacobi steps (set name -> :func:`cranefmu.host_steps.measured`'s entry) if
    ``composed`` is a shipped scene's own source (``ssp/<scene>/scene.toml``); {} for any other source."""
    from .. import build as b
    from ..host_steps import measured

    name = composed.source.name
    try:
        shipped = composed.source.path.resolve().parent == (b.SSP_SOURCES / name).resolve()
    except OSError:
        return {}
    return measured(name) if shipped else {}


def _shipped_host_step(composed: Composed) -> float | None:
    """The default set's measured stable plain-Jacobi step of a shipped scene's source; None otherwise."""
    found = _shipped_host_steps(composed).get("default")
    return found["step"] if found else None


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


def main(args: argparse.Namespace) -> int:
    from .. import whole_file

    for given, what, suffixes in ((args.output, "--output", (".ssp",)), (args.ssd, "--ssd", ())):
        if given is not None:
            whole_file.check(given, what, suffixes)   # before any build
    composed = built(Path(args.source))
    path = pack(composed, Path(args.output or f"{composed.source.name}.ssp"))   # the settled start --osp reads
    print(f"wrote {path} (scene {composed.source.name}: {len(composed.source.components)} components)")
    if args.ssd:
        whole_file.write(args.ssd, composed.ssd, "--ssd")
        print(f"wrote {args.ssd}")
    if args.osp:
        print(f"wrote {write_osp(composed, Path(args.osp), path)}")
    return 0
