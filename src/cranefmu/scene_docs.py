"""docs/scenes_catalog.md, generated from the scenes themselves, so the page cannot drift.

Every shipped scene (``ssp/<scene>/``) gets a section: its ``about.md`` (the hand-written part: what it
models, beside its ``scene.toml``), then what the code and the built scene say: question and source
(:data:`cranefmu.scenes.SCENES`), components and their roles, default stop time and stop conditions, power
bonds, parameter sets with their changes from the default set, key outputs and figures, fidelity switches,
the stored run settings (the scene file's, and a set's own), the measured choice and fidelity ladder
(``fidelity.json``, written by ``benchmarks/scene_defaults.py``) and the listed modes with their closed forms at
the default parameters (:data:`cranefmu.modal.MODES`).  Nothing volatile is written.

    python -m cranefmu.scene_docs [--output docs/scenes_catalog.md] [--check]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .sources import CHECKOUT, IN_CHECKOUT

PAGE = CHECKOUT / "docs" / "scenes_catalog.md"
ABOUT = "about.md"   # the hand-written part of a scene's section, in its folder
COMMAND = "python -m cranefmu.scene_docs"


def _pct(x) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.2g} %"


def _num(x) -> str:
    return f"{x:.5g}" if isinstance(x, float) else str(x)


def _md(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _scene(name: str):
    """The scene as a run reads it (its built .ssp with the pythonfmu FMUs: their model descriptions give the
    units and switch names), built first if stale."""
    from .master.extracted import extracted_scene
    from .scene_catalog import resolve

    return extracted_scene(resolve(name, fmus="python"))[1]


def settings_text(settings: dict) -> str:
    """Stored run settings as the table shows them: ``jacobi x2, 5 ms`` and any other setting by name."""
    rest = {k: v for k, v in settings.items() if k not in ("algorithm", "extrapolation", "step_size")}
    head = str(settings.get("algorithm", "jacobi"))
    if "extrapolation" in settings:
        head += f" x{settings['extrapolation']}"
    if "step_size" in settings:
        head += f", {_num(1000 * settings['step_size'])} ms"
    extra = ", ".join(f"{k} = {','.join(v) if isinstance(v, (list, tuple)) else v}" for k, v in rest.items())
    return head + (f", {extra}" if extra else "") if settings else "none"


def summary_rows(scenes: dict, link: str = "") -> list[str]:
    """The table of every scene, each name linked to ``link#name`` (README.md carries the same rows with
    ``link`` = docs/scenes_catalog.md)."""
    from .scenes import SCENES

    rows = ["| scene | components | question | default stop | power bonds | stored run settings |",
            "| --- | --- | --- | --- | --- | --- |"]
    for name, scene in scenes.items():
        info = SCENES.get(name)
        parts = " + ".join(c.fmu.stem for c in scene.components)
        bonds = ", ".join(b for b, _ in scene.bonds) or "none"
        stop = f"{_num(scene.stop_time)} s" if scene.stop_time is not None else "-"
        rows.append(f"| [`{name}`]({link}#{name}) | {parts} | {_md(info.question) if info else ''} | {stop} | {bonds} "
                    f"| {settings_text(scene.settings)} |")
    return rows


def _value(key: str, value, units: dict[str, str], switches: dict[str, dict[int, str]]) -> str:
    """A parameter value with its unit (6 significant digits), a switch as ``code (name)``."""
    if key in switches and value in switches[key]:
        return f"{value} ({switches[key][value]})"
    text = f"{value:.6g}" if isinstance(value, float) else str(value)
    return f"{text} {units.get(key, '')}".rstrip()


def _zeta(zeta: float) -> str:
    """A damping ratio to 4 digits; below 1e-4 (an undamped mode's eigenvalue round-off) as such."""
    return "0" if zeta == 0 else f"{zeta:.4g}" if abs(zeta) >= 1e-4 else "< 1e-4"


def _parameter_sets(scene) -> list[str]:
    from .scene_info import _fmu_facts

    units, switches, _, _ = _fmu_facts(scene)
    driven, default = scene.driven_inputs, scene.model_values()
    lines = ["- Parameter sets: " + ", ".join(f"`{s}`" for s in ["default", *scene.parameter_sets])
             + (" (the changes of each from `default`, settled start values left out):" if scene.parameter_sets
                else ".")]
    for set_name, values in scene.parameter_sets.items():
        changed = {k: v for k, v in values.items() if k not in driven and (k not in default or default[k] != v)}
        text = "; ".join(f"`{k}` {_value(k, default[k], units, switches) if k in default else '(not set)'} -> "
                         f"{_value(k, v, units, switches)}" for k, v in changed.items())
        lines.append(f"  - `{set_name}`: {text or 'no change'}")
    return lines


def _stored(name: str, scene) -> list[str]:
    from .scene_catalog import fidelity

    lines = [f"- Stored run settings (used where a run gives none): {settings_text(scene.settings)}"]
    lines += [f"  - parameter set `{s}` stores its own over them: {settings_text(own)}"
              for s, own in scene.set_settings.items()]
    data = fidelity(name)
    if not data:
        return lines + ["  - not measured (no entry in `fidelity.json`)"]
    best = data["chosen"]
    lines.append(f"  - measured over {_num(data['span'])} s against the monolith ({data['measured']}): chosen "
                 + (f"{best['label']}, range error {_pct(best['worst'])}, listed modes' frequency error "
                    f"{_pct(best['freq_err'])}, damping-ratio error {_pct(best['damp_err'])}" if best else
                    "none (no measured setting meets every limit)"))
    lines += ["", "  Fidelity ladder (fastest to most faithful, as measured; speed: "
              "[benchmarks/results/kinds_speed.md](../benchmarks/results/kinds_speed.md)):", "",
              "  | setting | range error | frequency error | damping-ratio error | passes |",
              "  | --- | --- | --- | --- | --- |"]
    lines += [f"  | {r['label']} | {_pct(r['worst'])} | {_pct(r['freq_err'])} | {_pct(r['damp_err'])} | "
              f"{'yes' if r['ok'] else 'no'} |" for r in data["ladder"]]
    return lines


def mode_rows(name: str) -> list[str]:
    """One table row per listed mode of scene ``name``: its closed form at the default parameters."""
    from . import modal

    specs = modal.specs(name)
    if not specs:
        return []
    values = modal.scene_values(name)
    rows = []
    for spec in specs:
        f, zeta = spec.closed_form({**values, **spec.probe})
        probe = ", ".join(f"`{k} = {_num(v)}`" for k, v in spec.probe.items()) or "the scene as it is"
        fitted = f"`{spec.column}`" + (f" ({spec.n_fit} modes fitted)" if spec.n_fit > 1 else "")
        rows.append(f"| {spec.name} | {fitted} | {_num(spec.span)} s, {probe} | {_md(spec.formula)} | "
                    f"{f:.5g} Hz | {_zeta(zeta)} |")
    return rows


def scene_section(name: str, scene, scene_dir: Path | None) -> list[str]:
    """The section of one scene: its about.md, then the generated facts."""
    from .scenes import SCENES

    info = SCENES.get(name)
    about = scene_dir / ABOUT if scene_dir is not None else None
    lines = [f"## {name}", ""]
    if about is not None and about.is_file():
        lines += [about.read_text().strip(), ""]
    if info:
        lines.append(f"- Question: {info.question}.")
        if info.paper:
            lines.append(f"- Source: {info.paper}.")
    roles = {c[0]: c[2] for c in info.components} if info else {}
    lines.append("- Components: " + "; ".join(f"`{c.name}` ({c.fmu.stem}" + (f": {roles[c.name]})" if c.name in roles
                                                                              else ")") for c in scene.components)
                 + ".")
    lines.append(f"- Default stop time: {_num(scene.stop_time)} s." if scene.stop_time is not None
                 else "- Default stop time: none stated.")
    lines += [f"- Stop condition: `{k}` ({v})." for k, v in scene.stop_conditions.items()]
    lines.append("- Power bonds: " + (", ".join(f"`{b}`" for b, _ in scene.bonds) or "none") + ".")
    lines += _parameter_sets(scene)
    if info:
        lines.append("- Key outputs: " + ", ".join(f"`{k}`" for k in info.key_outputs) + ".")
        if info.plots:
            lines.append("- Figures (`--plot`): " + "; ".join(f"{title} ({', '.join(cols)})" for title, cols in info.plots)
                         + ".")
        if info.fidelity:
            lines.append("- Fidelity switches (`--set comp.var=name`): "
                         + "; ".join(f"`{k}` ({v})" for k, v in info.fidelity.items()) + ".")
    lines += _stored(name, scene)
    rows = mode_rows(name)
    if rows:
        lines += ["", "Listed modes (closed form at the default parameters; the check is against the monolith "
                  "over the same probe run):", "",
                  "| mode | output fitted | probe run | closed form | f | zeta |", "| --- | --- | --- | --- | --- | --- |",
                  *rows]
    else:
        lines.append("- Listed modes: none (`cranefmu.modal.MODES`).")
    return lines + [""]


def _limits() -> str:
    from . import modal

    return (f"frequency error <= {_num(100 * modal.FREQ_LIMIT)} %, damping-ratio error <= "
            f"{_num(100 * modal.DAMP_LIMIT)} % of max(zeta_ref, {_num(modal.ZETA_FLOOR)})")


def render() -> str:
    """The whole page."""
    from .sources import scene_dirs

    dirs = {d.name: d for d in scene_dirs()}
    scenes = {name: _scene(name) for name in dirs}
    head = [
        "# The scenes",
        "",
        f"<!-- generated by `{COMMAND}` from ssp/<scene>/ (about.md, scene.toml, .ssv), cranefmu.scenes.SCENES, "
        "cranefmu.modal.MODES and src/cranefmu/fidelity.json: edit those, not this page -->",
        "",
        f"The {len(scenes)} scenes shipped with cranefmu: what each models and answers, its parameter sets, key "
        "outputs, stored run settings and listed modes. The file format is in [docs/scenes.md](scenes.md), the "
        "numbers against the papers in [docs/validation.md](validation.md); `cranefmu info SCENE` prints the same "
        "facts with every parameter, output and connection. A scene's hand-written text is `ssp/<scene>/about.md`.",
        "",
        *summary_rows(scenes),
        "",
        "A stored setting is the cheapest measured (`benchmarks/scene_defaults.py`) whose key outputs stay within "
        "1 % of range of the monolithic solve and that keeps every listed mode: each mode is fitted from a run's "
        "output by a matrix pencil (`cranefmu.modal.fit_modes`) and compared with the monolith fitted over the "
        f"same run ({_limits()}); no power bond's residual may exceed 10 % of the energy it carried. A mode the "
        "scene's own run does not excite has a probe: parameter changes that start it as a free vibration. How "
        "the settings were chosen over time: [benchmarks/results/history.md](../benchmarks/results/history.md).",
        "",
    ]
    body: list[str] = []
    for name, scene in scenes.items():
        body += scene_section(name, scene, dirs[name])
    tail = [
        "## From Python",
        "",
        "- `cranefmu.scenes.summary(name, result)`: the summary lines `cranefmu run` prints; `metrics(name, result)` "
        "the numbers; `plot_groups(name, columns)` the figures of `--plot`. A result is the master's structured "
        "array or `reference.solve`'s dict.",
        "- `cranefmu.reference.solve(scene, stop_time, times, parameter_set=\"default\", parameters=None)`: the "
        "same physics models wired into one ODE, solved with scipy (Radau by default), cut into smooth segments at "
        "the drive's clock breakpoints and the rope's regime switches; the reference of `cranefmu converge`, the "
        "stored settings and the validation report (`tests/scenes/test_reference.py`).",
        "- `cranefmu.modal`: `fit_modes(t, y, n)`, `check_setting(scene, settings)` (probe runs against the "
        "monolith), `check_settings(...)`; in a sweep the metrics `freq:COLUMN[~HZ]` and `damping:COLUMN[~HZ]`.",
        "- `benchmarks/validation_report.py` writes [docs/validation.md](validation.md) (`--quick` for a smoke run).",
        "",
    ]
    return "\n".join(head + body + tail)


def stale(path: Path = PAGE) -> bool:
    """True if ``path`` is not what :func:`render` writes."""
    return not path.is_file() or path.read_text() != render()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog=COMMAND, description="write docs/scenes_catalog.md from the scenes")
    p.add_argument("--output", default=None, help="the page (default: docs/scenes_catalog.md of the checkout)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if the page differs")
    args = p.parse_args(argv)
    if args.output is None and not IN_CHECKOUT:
        print(f"{COMMAND}: not in a checkout: give --output FILE", file=sys.stderr)
        return 2
    path = Path(args.output) if args.output else PAGE
    page = render()
    if args.check:
        if not path.is_file() or path.read_text() != page:
            print(f"{path} differs from the scenes: run {COMMAND}")
            return 1
        return 0
    path.write_text(page)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
