"""Each scene's measured speed at its stored settings over its whole natural length, per kind of FMU, as
``benchmarks/kinds_speed.py`` measured it (cold: the whole ``cranefmu run`` command; warm: a second run in
one process; CPU and wall [s]) into ``benchmarks/results/kinds_speed.md`` and, read from that table, into
``speed.json`` beside this module, which ``cranefmu info`` quotes (:func:`info_lines`)."""
from __future__ import annotations

import json
from pathlib import Path

STORE = Path(__file__).with_name("speed.json")   # written by benchmarks/kinds_speed.py from its table
TABLE = "benchmarks/results/kinds_speed.md"       # the table it is read from (in a checkout)
_KEYS = ("rtf_cold_cpu", "rtf_cold_wall", "rtf_warm_cpu", "rtf_warm_wall")


def parse_table(text: str) -> dict:
    """{"measured": the table's stamp line (commit, date, load, script), "note": its line on cores, rounds
    and load, "scenes": {scene: {"stop": [s], kind: {"rtf_cold_cpu", ... (the table's real-time factors),
    "cold_cpu", "cold_wall", "warm_cpu", "warm_wall" [s]}}}}
    from the text of kinds_speed.md."""
    lines = text.splitlines()
    stamp = next((ln for ln in lines if ln.startswith("Commit ")), "")
    note = next((ln for ln in lines if "cores shared" in ln), "")
    scenes: dict[str, dict] = {}
    for ln in lines:
        cells = [c.strip() for c in ln.strip().strip("|").split("|")]
        if len(cells) != 9 or cells[2] not in ("native", "python"):
            continue
        try:
            stop, rtfs = float(cells[1]), [float(c) for c in cells[3:7]]
            (cc, cw), (wc, ww) = ([float(x) for x in c.split("/")] for c in cells[7:9])
        except ValueError:
            continue
        scenes.setdefault(cells[0], {"stop": stop})[cells[2]] = {
            **dict(zip(_KEYS, rtfs)), "cold_cpu": cc, "cold_wall": cw, "warm_cpu": wc, "warm_wall": ww}
    if not scenes:
        raise ValueError("kinds_speed table: no row of the form '| scene | T | kind | ... | CPU / wall | CPU / wall |'")
    return {"measured": stamp, "note": note, "scenes": scenes}


def write_from_table(table: Path, store: Path = STORE) -> dict:
    """Read ``table`` (kinds_speed.md) and write its numbers to ``store``; returns them."""
    data = parse_table(Path(table).read_text())
    store.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return data


def info_lines(scene: str, store: Path = STORE) -> list[str]:
    """``cranefmu info`` lines: the scene's real-time factors (simulated time / CPU, and / wall) cold and warm
    per kind of FMU, with where and when they were measured; one line saying so when not measured."""
    data = json.loads(store.read_text()) if store.is_file() else {}
    row = data.get("scenes", {}).get(scene)
    if not row:
        return ["  speed: not measured for this scene (benchmarks/kinds_speed.py)"]
    t = row["stop"]
    lines = [f"  speed at the stored settings over the whole {t:g} s, real-time factor = simulated time / time "
             f"({TABLE}: {data['measured']}; {data['note']}):"]
    for kind in ("native", "python"):
        if kind in row:
            r = row[kind]
            lines.append(f"    {kind} FMUs: cold (the whole cranefmu run command) {r['rtf_cold_cpu']:g}x on CPU, "
                         f"{r['rtf_cold_wall']:g}x on the wall; warm (a second run in one process) "
                         f"{r['rtf_warm_cpu']:g}x on CPU, {r['rtf_warm_wall']:g}x on the wall")
    return lines
