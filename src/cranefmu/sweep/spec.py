"""The design of a sweep: which inputs vary over which values, and the list of runs it makes.

An input is a scene parameter ``comp.var`` or a run setting (a field of
:class:`cranefmu.master.run.Settings`, e.g. ``step_size``, ``algorithm``, ``extrapolation``,
``adaptive``, ``tolerance``) or ``parameter_set``.  Values are written as

- ``v1,v2,...``       a list (numbers or words);
- ``start:stop:n``    n values evenly spaced from start to stop (both included);
- ``log:start:stop:n`` n values evenly spaced in log10 (both > 0);
- a list-valued setting (``implicit``, ``order``, ``stop_when``) varies over values separated by ``;``,
  each a comma-separated list (``none``: the empty one), e.g. ``implicit=none;tip;tip,hook``.

A setting's text is converted through its field's own type (:func:`cranefmu.master.settings.convert`).

A parameter's values may carry a unit (:func:`cranefmu.adapter.units.quantity`): after each value (``30 deg,45 deg``)
or once after the list or range (``30,45,60 deg``, ``30:60:4 deg``), one unit for all values of an input.
The run gets the value in SI (the FMU's unit, checked by the engine); the table shows it as given, its
column named with the unit (``boom.luff_angle [deg]``).

A design is the full factorial of the values, or a sample of N points (Latin hypercube or Sobol,
:mod:`scipy.stats.qmc`) in the unit cube mapped onto each input: a range linearly (log ranges in
log10) between its ends, a list by index (floor(u k) of its k values); ``n`` of a range is then unused.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field, replace

from dataclasses import fields as _fields

from ..errors import SettingsError
from ..master.settings import Settings, convert as convert_setting, is_list, kind_of

DESIGNS = ("factorial", "lhs", "sobol")
# run settings a sweep may vary or fix: every field of Settings but progress (display only)
SETTINGS = tuple(f.name for f in _fields(Settings) if f.name != "progress") + ("parameter_set",)


def number(text: str) -> float | None:
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def convert(name: str, text: object) -> object:
    """The value of input ``name`` from text: a setting to its type, a parameter to a float when it reads
    as a number (else the text, e.g. ``rope.model=bouc_wen``)."""
    if not isinstance(text, str):
        return text
    if name == "parameter_set":
        return text.strip()
    if name in SETTINGS:
        return convert_setting(name, text)
    v = number(text.strip())
    return text.strip() if v is None else v


def split_unit(name: str, parts: list[str]) -> tuple[list[str], str]:
    """(the parts' number texts, the one unit written on any of them, or ""): ``30 deg`` or ``30`` beside a
    part that names the unit; two units for one input, or a unit on a run setting, are refused."""
    from ..adapter import units

    texts, written = [], set()
    for part in parts:
        p = part.strip()
        if units.is_quantity(p):
            m = units._QUANTITY.match(p)
            texts.append(m.group(1))
            written.add(m.group(2).strip())
        else:
            texts.append(p)
    if len(written) > 1:
        raise SettingsError(f"--vary {name}: units {', '.join(sorted(written))} are not allowed together: one unit "
                            "for all values of an input")
    unit = written.pop() if written else ""
    if unit and "." not in name:
        raise SettingsError(f"{name}: a unit ({unit!r}) is not allowed on a run setting: give it in SI "
                            "(a unit is allowed on a parameter's values)")
    return texts, unit


def label(name: str, unit: str) -> str:
    """The table's column of input ``name`` given in ``unit``: ``boom.luff_angle [deg]`` (the name alone without one)."""
    return f"{name} [{unit}]" if unit else name


def check_name(name: str) -> None:
    comp, dot, var = name.partition(".")
    if dot and comp and var:
        return
    if name not in SETTINGS:
        raise SettingsError(f"input {name!r} is not allowed: a parameter 'component.variable' or a run setting, "
                            f"one of {', '.join(SETTINGS)}")


@dataclass(frozen=True)
class Factor:
    """One varied input: its values (a list), or a range [low, high] (log10 if ``log``) of ``n`` values."""

    name: str
    values: tuple = ()
    low: float | None = None
    high: float | None = None
    n: int = 0
    log: bool = False
    unit: str = ""      # the unit the values are written in ("": SI, the FMU's own)
    also: tuple = ()    # more inputs that take the same value in every run (``a,b=values``: varied together)

    @property
    def names(self) -> tuple[str, ...]:
        return (self.name, *self.also)

    def __post_init__(self):
        for name in self.names:
            check_name(name)
        if self.low is None:
            if not self.values:
                raise SettingsError(f"--vary {self.name}: no values given")
            return
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise SettingsError(f"--vary {self.name}: range {self.low}:{self.high} is not allowed: finite ends")
        if self.log and (self.low <= 0 or self.high <= 0):
            raise SettingsError(f"--vary {self.name}: log range {self.low:g}:{self.high:g} is not allowed: ends > 0")
        if self.name == "parameter_set" or (self.name in SETTINGS and kind_of(self.name) is not float):
            raise SettingsError(f"--vary {self.name}: a range is not allowed for this setting, give a list")

    @property
    def levels(self) -> list:
        """The factorial levels: the list, or n values over the range."""
        if self.low is None:
            return list(self.values)
        if self.n < 1:
            raise SettingsError(f"--vary {self.name}: a factorial design needs the number of values, "
                                f"e.g. {self.low:g}:{self.high:g}:5")
        if self.n == 1:
            return [self.low]
        if self.log:
            a, b = math.log10(self.low), math.log10(self.high)
            return [10.0 ** (a + (b - a) * i / (self.n - 1)) for i in range(self.n)]
        return [self.low + (self.high - self.low) * i / (self.n - 1) for i in range(self.n)]

    def at(self, u: float) -> object:
        """The value at u in [0, 1) of a sample."""
        if self.low is None:
            return self.values[min(int(u * len(self.values)), len(self.values) - 1)]
        if self.log:
            a, b = math.log10(self.low), math.log10(self.high)
            return 10.0 ** (a + (b - a) * u)
        return self.low + (self.high - self.low) * u


def parse_factor(text: str) -> Factor:
    """'comp.var=v1,v2' | 'comp.var=start:stop:n' | 'comp.var=log:start:stop:n' (stop/n optional in samples);
    'a.x,b.y=...': both inputs take each value together (a boom held at each length: its start and end)."""
    names, sep, spec = str(text).partition("=")
    spec = spec.strip()
    name, *also = [n.strip() for n in names.split(",")]
    if not sep or not name or not spec or not all(also):
        raise SettingsError(f"--vary {text!r} is not allowed: write NAME=v1,v2,... or NAME=start:stop:n or "
                            "NAME=log:start:stop:n (NAME,NAME2=... varies two inputs together)")
    for n in (name, *also):
        check_name(n)
    if len({name, *also}) != 1 + len(also):
        raise SettingsError(f"--vary {text!r} is not allowed: each input at most once")
    return replace(_parse_values(text, name, spec), also=tuple(also))


def _parse_values(text: str, name: str, spec: str) -> Factor:
    parts = spec.split(":")
    log = parts[0].strip().lower() == "log"
    if log:
        parts = parts[1:]
    if log or (len(parts) in (2, 3) and "," not in spec):
        parts, unit = split_unit(name, parts)
        nums = [number(p) for p in parts]
        if len(parts) not in (2, 3) or any(v is None for v in nums) or (len(nums) == 3 and
                                                                        (nums[2] < 1 or nums[2] != int(nums[2]))):
            raise SettingsError(f"--vary {text!r} is not allowed: a range is start:stop:n (n an integer >= 1), "
                                "log:start:stop:n for log spacing")
        return Factor(name, low=nums[0], high=nums[1], n=int(nums[2]) if len(nums) == 3 else 0, log=log, unit=unit)
    texts = spec.split(";" if name in SETTINGS and is_list(name) else ",")
    texts, unit = split_unit(name, texts) if "." in name else (texts, "")
    values = tuple(convert(name, v) for v in texts)
    if unit and not all(isinstance(v, float) for v in values):
        raise SettingsError(f"--vary {text!r} is not allowed: a unit ({unit!r}) needs numbers")
    if len(set(map(repr, values))) != len(values):
        raise SettingsError(f"--vary {text!r} is not allowed: each value at most once")
    return Factor(name, values=values, unit=unit)


@dataclass(frozen=True)
class Run:
    """One run of a sweep: the scene, its inputs (varied and fixed), and the key that names it."""

    scene: str
    inputs: dict = field(hash=False)   # name -> value: 'comp.var' parameters and run settings, as given
    request: str = ""   # digest of everything else the run's result depends on (:func:`.request.digest`)
    units: tuple = ()   # (name, unit) of the inputs given in a unit (their values in ``inputs`` are in it)

    @property
    def parameters(self) -> dict:
        """The parameters the run takes: a value given in a unit converted to SI."""
        return {k: v for k, v in self.si_inputs.items() if "." in k}

    @property
    def si_inputs(self) -> dict:
        """``inputs`` with each value given in a unit in SI (what the run and a Custom metric see)."""
        from ..adapter import units

        given = dict(self.units)
        return {k: v * units.parse(given[k])[0] if k in given else v for k, v in self.inputs.items()}

    @property
    def row(self) -> dict:
        """The inputs as the table shows them: as given, under :func:`label` (``boom.luff_angle [deg]``)."""
        given = dict(self.units)
        return {label(k, given.get(k, "")): v for k, v in self.inputs.items()}

    @property
    def settings(self) -> dict:
        return {k: v for k, v in self.inputs.items() if "." not in k and k != "parameter_set"}

    @property
    def parameter_set(self) -> str | None:
        return self.inputs.get("parameter_set")

    @property
    def key(self) -> str:
        """A hash of the scene, every input (sorted, values by repr) and the request digest: the same
        run has the same key in any order and any session, so a resumed sweep can skip it, and a run
        whose scene file, code or effective settings changed has another key, so it runs again."""
        text = json.dumps([self.scene, sorted((k, repr(v)) for k, v in self.inputs.items())]
                          + ([self.request] if self.request else []) + ([sorted(self.units)] if self.units else []))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Design:
    """The varied inputs, the fixed ones, and how they are combined (full factorial or N samples)."""

    factors: tuple[Factor, ...]
    fixed: dict = field(default_factory=dict, hash=False)
    listed: tuple = ()   # explicit points (dicts of inputs) instead of factors
    kind: str = "factorial"
    samples: int | None = None
    seed: int = 0
    fixed_units: dict = field(default_factory=dict, hash=False)   # fixed input -> the unit its value is given in

    def __post_init__(self):
        if self.kind not in DESIGNS:
            raise SettingsError(f"design = {self.kind!r} is not allowed: one of {', '.join(DESIGNS)}")
        if self.listed and self.factors:
            raise SettingsError("give either varied inputs or a list of points, not both")
        for p in self.listed:
            for name in p:
                check_name(name)
        names = [n for f in self.factors for n in f.names]
        if len(set(names)) != len(names):
            raise SettingsError(f"an input is varied twice: {', '.join(sorted({n for n in names if names.count(n) > 1}))}")
        for name in self.fixed:
            check_name(name)
        both = (set(names) | {k for p in self.listed for k in p}) & set(self.fixed)
        if both:
            raise SettingsError(f"input(s) {', '.join(sorted(both))} both varied and fixed: give one")
        if self.kind != "factorial" and (not isinstance(self.samples, int) or self.samples < 1):
            raise SettingsError(f"samples = {self.samples!r} is not allowed with design {self.kind!r}: an integer >= 1")
        if self.kind == "factorial" and self.samples is not None:
            raise SettingsError("samples is only allowed with design 'lhs' or 'sobol'")

    @property
    def names(self) -> list[str]:
        """The varied inputs in order (of listed points: every name any point has)."""
        return list(dict.fromkeys(k for p in self.listed for k in p)) if self.listed else \
            [n for f in self.factors for n in f.names]

    def points(self) -> list[dict]:
        """Each run's varied inputs, in a fixed order."""
        if self.listed:
            return [dict(p) for p in self.listed]
        if not self.factors:
            return [{}]
        if self.kind == "factorial":
            grid = itertools.product(*(f.levels for f in self.factors))
            return [{n: v for f, v in zip(self.factors, combo) for n in f.names} for combo in grid]
        from scipy.stats import qmc

        d = len(self.factors)
        sampler = qmc.LatinHypercube(d, seed=self.seed) if self.kind == "lhs" else \
            qmc.Sobol(d, scramble=True, seed=self.seed)
        u = sampler.random(self.samples)
        return [{n: f.at(float(x)) for f, x in zip(self.factors, row) for n in f.names} for row in u]

    @property
    def units(self) -> dict[str, str]:
        """name -> the unit its values are given in (only inputs given with one)."""
        out = {n: f.unit for f in self.factors if f.unit for n in f.names}
        out.update(self.fixed_units)
        return out

    def label(self, name: str) -> str:
        return label(name, self.units.get(name, ""))

    def runs(self, scene: str) -> list[Run]:
        given = tuple(sorted(self.units.items()))
        return [Run(scene, {**self.fixed, **p}, units=tuple((k, u) for k, u in given if k in {**self.fixed, **p}))
                for p in self.points()]


def design(vary: list[str] | list[dict] | dict | None = None, fixed: dict | None = None, kind: str = "factorial",
           samples: int | None = None, seed: int = 0) -> Design:
    """A design from ``--vary`` texts, a dict name -> list of values, or a list of points (dicts name ->
    value, run as given), and the fixed inputs name -> value."""
    fixed, fixed_units = dict(fixed or {}), {}
    for k, v in fixed.items():
        if isinstance(v, str) and "." in k:
            (text,), unit = split_unit(k, [v])
            if unit:
                fixed_units[k] = unit
                v = number(text) if number(text) is not None else v
        fixed[k] = convert(k, v)
    if isinstance(vary, (list, tuple)) and vary and all(isinstance(p, dict) for p in vary):
        listed = tuple({k: convert(k, v) for k, v in p.items()} for p in vary)
        return Design((), fixed, kind=kind, samples=samples, seed=seed, listed=listed, fixed_units=fixed_units)
    if isinstance(vary, dict):
        factors = []
        for k, v in vary.items():
            if isinstance(v, str):
                factors.append(parse_factor(f"{k}={v}"))
            else:
                name, *also = [n.strip() for n in str(k).split(",")]   # "a,b": varied together
                factors.append(Factor(name, values=tuple(convert(name, x) for x in v), also=tuple(also)))
    else:
        factors = [parse_factor(t) for t in (vary or [])]
    return Design(tuple(factors), fixed, kind=kind, samples=samples, seed=seed, fixed_units=fixed_units)
