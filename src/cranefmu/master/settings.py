"""Every run setting, defined once: default, meaning, unit, type and command-line form.

:class:`Settings` is the single source: :func:`cranefmu.master.run.run` takes its fields as keywords
(its signature and docstring are built from them), ``cranefmu run`` builds its options and their
``--help`` from the same fields (:func:`add_arguments`), and every text value (an option, a sweep's
``--set``/``--vary``, a scene's stored settings) is converted by :func:`convert` through the field's
type, booleans by :func:`parse_bool`.  Which value a run takes, and where it came from (given, the
scene, the algorithm's default, the default here), is decided once by
:func:`cranefmu.master.runspec.resolve`.
"""
from __future__ import annotations

import argparse
import math
from dataclasses import MISSING, dataclass, field, fields

from ..errors import SettingsError
from .acceleration import ACCELERATORS

ALGORITHMS = ("jacobi", "gauss-seidel", "iterative", "jacobi-plain")  # made by algorithm_table.make_algorithm
STEP_CONTROLS = ("extrapolation", "ecco")
FMU_KINDS = ("native", "python")   # the kinds of FMU a scene given by name runs with (.fmu_kind)
DEFAULT_STOP_TIME = 10.0   # [s] of a scene whose DefaultExperiment states none


def setting(default, help: str, *, type=None, flag: str | None = None, metavar: str | None = None,
            form: str = "value", flag_help: str | None = None):
    """A settings field.  ``form``: value (``--flag VALUE``), switch (``--flag`` sets True), negate
    (``--no-flag`` sets False), off (``--no-flag`` sets False, default None = automatic), list
    (comma-separated names; for stop_when 'none' is the empty list).  ``flag_help``: the option's
    help where it differs from the setting's (a --no- option)."""
    return field(default=default, metadata=dict(help=help, type=type, flag=flag, metavar=metavar, form=form,
                                                 flag_help=flag_help))


@dataclass(frozen=True)
class Settings:
    """Every run setting; :meth:`check` validates them once the scene's stop time is known."""

    stop_time: float | None = setting(None, "end of the run [s] (default: the scene's DefaultExperiment, else 10)",
                                      type=float)
    step_size: float = setting(1e-3, "macro (communication) step [s]; the first step with adaptive", type=float,
                               flag="--step")
    algorithm: str = setting("jacobi", "coupling: " + ", ".join(ALGORITHMS) + " (iterative: strong coupling with "
                             "rollback; jacobi-plain: libcosim's fixed-step Jacobi, no feedthrough re-read)", type=str)
    extrapolation: int = setting(0, "order of the polynomial the coupling inputs follow inside a step: 0, 1, 2 "
                                 "(iterative: degree of the interpolation; 0 holds the end value over the "
                                 "step, an implicit coupling that damps a stiff spring's modes H cannot resolve; "
                                 "first order)", type=int)
    start_time: float = setting(0.0, "start of the run [s]", type=float)
    adaptive: bool = setting(False, "control the macro step (step_size is the first step)", form="switch")
    tolerance: float = setting(1e-3, "adaptive: relative local error of the coupling values per step", type=float)
    min_step: float | None = setting(None, "adaptive: smallest step [s] (default step/1000); also how finely a "
                                     "switching discrete output is located", type=float)
    max_step: float | None = setting(None, "adaptive: largest step [s] (default 100 steps)", type=float)
    step_control: str = setting("extrapolation", "adaptive: extrapolation (error of the extrapolated coupling "
                                "values, rejecting) or ecco (power-bond energy residuals, never rejecting)", type=str)
    coupling_tolerance: float = setting(1e-8, "iterative: relative residual of the coupling values at which a "
                                        "step has converged", type=float)
    max_iterations: int = setting(50, "iterative: iterations per step", type=int)
    accelerator: str = setting("iqn-ils", "iterative: " + ", ".join(ACCELERATORS), type=str)
    order: list[str] | None = setting(None, "gauss-seidel: the order the components step in (default: from the "
                                      "dependency graph)", metavar="COMP,COMP,...", form="list")
    energy_alarm: float | None = setting(None, "stop when a power bond's total energy residual exceeds this [J]",
                                         type=float, metavar="JOULES")
    init_tolerance: float = setting(1e-10, "relative agreement of the connections after initialization",
                                    type=float)
    progress: bool | None = setting(None, "progress bar (default: on a terminal, for runs longer than 3 s)",
                                    form="off", flag_help="no progress bar (it shows on a terminal only, for "
                                    "runs longer than 3 s)")
    substeps: int = setting(1, "iterative: waveform iteration on this many sub-intervals of each macro step "
                            "(1: one input polynomial per step)", type=int, metavar="M")
    instability_alarm: bool = setting(True, "stop a run whose explicit coupling is unstable (a power bond's "
                                      "residual grows geometrically, or a coupling value's change per step)",
                                      form="negate", flag_help="do not stop a run whose explicit coupling is "
                                      "unstable (the alarm is on by default)")
    implicit: list[str] | None = setting(None, "jacobi: couple these power bonds or components implicitly (their "
                                         "components form one group, solved by Newton to coupling_tolerance each "
                                         "step with rollback of only its FMUs; degree = extrapolation), the rest "
                                         "explicitly; e.g. foot_heave,tip",
                                         metavar="NAMES", form="list")
    stop_when: list[str] | None = setting(None, "end the run (as a result) at the first output time where one "
                                          "of these outputs 'component.variable' is non-zero (default: the "
                                          "scene's own stop conditions; 'none' or [] runs on)", metavar="VARS",
                                          form="list")
    fmus: str | None = setting(None, "which FMUs run a scene given by name: native (C) or python (pythonfmu, the "
                               "reference); default: native where built or buildable (a C compiler), else python "
                               "with one line saying why; a scene file runs the FMUs it holds", type=str,
                               metavar="native|python")

    def check(self) -> None:
        """Refuse a bad value (or combination) with a :class:`SettingsError` naming it."""
        if self.fmus not in (None, *FMU_KINDS):
            raise SettingsError(f"fmus = {self.fmus!r} is not allowed: native or python")
        if not isinstance(self.instability_alarm, bool):
            raise SettingsError(f"instability_alarm = {self.instability_alarm!r} is not allowed: True or False")
        if self.stop_when is not None and (isinstance(self.stop_when, str) or
                                           not all(isinstance(v, str) for v in self.stop_when)):
            raise SettingsError(f"stop_when = {self.stop_when!r} is not allowed: a list of output names "
                                "'component.variable' (empty: run on)")
        if self.implicit is not None:
            if isinstance(self.implicit, str) or not all(isinstance(v, str) and v for v in self.implicit):
                raise SettingsError(f"implicit = {self.implicit!r} is not allowed: a list of power-bond or "
                                    "component names")
            if self.implicit and self.algorithm != "jacobi":
                raise SettingsError(f"implicit = {self.implicit!r} is not allowed with algorithm = "
                                    f"{self.algorithm!r}: only with 'jacobi' (iterative couples everything implicitly)")
        for name in ("start_time", "stop_time", "step_size", "tolerance", "coupling_tolerance", "init_tolerance"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SettingsError(f"{name} = {value!r} is not allowed: a finite number")
        if self.stop_time <= self.start_time:
            raise SettingsError(f"stop_time = {self.stop_time!r} is not allowed: must be > start_time = "
                                f"{self.start_time!r} s")
        span = self.stop_time - self.start_time
        if self.step_size <= 0:
            raise SettingsError(f"step_size = {self.step_size!r} is not allowed: must be > 0 s")
        if self.step_size > span:
            raise SettingsError(f"step_size = {self.step_size!r} is not allowed: must be <= stop_time - start_time "
                                f"= {span!r} s")
        if self.algorithm not in ALGORITHMS:
            raise SettingsError(f"algorithm = {self.algorithm!r} is not allowed: one of {', '.join(ALGORITHMS)}")
        if isinstance(self.extrapolation, bool) or self.extrapolation not in (0, 1, 2):
            raise SettingsError(f"extrapolation = {self.extrapolation!r} is not allowed: 0, 1 or 2")
        for name in ("tolerance", "coupling_tolerance", "init_tolerance"):
            if not 0 < getattr(self, name) < 1:
                raise SettingsError(f"{name} = {getattr(self, name)!r} is not allowed: between 0 and 1 (relative)")
        if self.step_control not in STEP_CONTROLS:
            raise SettingsError(f"step_control = {self.step_control!r} is not allowed: one of "
                                f"{', '.join(STEP_CONTROLS)}")
        if self.accelerator not in ACCELERATORS:
            raise SettingsError(f"accelerator = {self.accelerator!r} is not allowed: one of {', '.join(ACCELERATORS)}")
        for name in ("max_iterations", "substeps"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise SettingsError(f"{name} = {value!r} is not allowed: an integer >= 1")
        if self.order and self.algorithm != "gauss-seidel":   # silently unused otherwise
            raise SettingsError(f"order = {','.join(map(str, self.order))!r} is not allowed with algorithm = "
                                f"{self.algorithm!r}: only with 'gauss-seidel' (the others step every component "
                                "at once)")
        if self.substeps > 1 and self.algorithm != "iterative":
            raise SettingsError(f"substeps = {self.substeps!r} is not allowed with algorithm = {self.algorithm!r}: "
                                "only with 'iterative' (waveform iteration); use 1")
        for name in ("min_step", "max_step", "energy_alarm"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                      or not math.isfinite(value) or value <= 0):
                raise SettingsError(f"{name} = {value!r} is not allowed: a number > 0 (or None)")
        if self.adaptive and self.h_min > self.step_size:
            raise SettingsError(f"min_step = {self.h_min!r} is not allowed: must be <= step_size = {self.step_size!r} s")
        if self.adaptive and self.h_max < self.step_size:
            raise SettingsError(f"max_step = {self.h_max!r} is not allowed: must be >= step_size = {self.step_size!r} s")

    @property
    def h_min(self) -> float:
        return self.min_step if self.min_step is not None else 1e-3 * self.step_size

    @property
    def h_max(self) -> float:
        span = self.stop_time - self.start_time
        return self.max_step if self.max_step is not None else min(span, 100 * self.step_size)

    def rows_expected(self) -> float:
        """Rows a run writes: one per step plus the start (adaptive: at the first step's size)."""
        return math.floor((self.stop_time - self.start_time) / self.step_size + 0.5) + 1


def describe() -> str:
    """One line per setting (for docstrings): ``name = default: meaning``."""
    return "\n".join(f"    {f.name} = {f.default!r}: {f.metadata['help']}" for f in fields(Settings))


def flag_of(f) -> str:
    base = f.metadata["flag"] or "--" + f.name.replace("_", "-")
    return "--no-" + base[2:] if f.metadata["form"] in ("negate", "off") else base


def add_arguments(parser: argparse.ArgumentParser, names: tuple[str, ...] | None = None,
                  absent: bool = True) -> None:
    """One option per setting (or per setting of ``names``), its help from the field.  ``absent``:
    an option not given stays out of the namespace (the field's default rules when the settings are
    built); else it takes the field's default.  Either way defaults live in :class:`Settings` only."""
    for f in fields(Settings):
        if names is not None and f.name not in names:
            continue
        meta, form = f.metadata, f.metadata["form"]
        shown = "" if f.default in (None, MISSING) or form in ("negate", "off", "switch") \
            else f"{f.default:g}" if isinstance(f.default, float) else f"{f.default}"
        # not given, a run takes the scene's stored value (runspec.resolve): say so where a scene may store it
        default = "" if not shown else f" (default: the scene's stored {f.name}, else {shown})" \
            if absent and f.name not in NOT_STORED else f" (default {shown})"
        common = dict(dest=f.name, default=argparse.SUPPRESS if absent else f.default, help=(meta["flag_help"] or meta["help"]) + default)
        if form == "switch":
            parser.add_argument(flag_of(f), action="store_true", **common)
        elif form in ("negate", "off"):
            parser.add_argument(flag_of(f), action="store_false", **common)
        else:
            kind = _comma_list if form == "list" else meta["type"]
            parser.add_argument(flag_of(f), type=kind, metavar=meta["metavar"], **common)


def _comma_list(text: str) -> list[str]:
    """'a,b' -> ['a', 'b']; 'none' -> [] (stop_when: run on)."""
    return [] if text.strip().lower() == "none" else [v.strip() for v in text.split(",") if v.strip()]


SCENE_ONLY = ("start_time", "stop_time")   # a scene states these in its DefaultExperiment
NOT_STORED = SCENE_ONLY + ("progress", "fmus")   # display and the kind of FMU, not a numerical choice


# the settings that choose the numerical method: a scene's stored ones were measured for its stored
# algorithm and are not taken by a run of another algorithm (runspec's stored-settings rule)
NUMERICAL = ("step_size", "extrapolation", "adaptive", "tolerance", "min_step", "max_step", "step_control",
             "coupling_tolerance", "max_iterations", "accelerator", "order", "implicit", "substeps",
             "init_tolerance")
# an algorithm's own defaults where they differ from the fields' (jacobi-plain: libcosim's zero-order hold)
ALGORITHM_DEFAULTS: dict[str, dict[str, object]] = {"jacobi-plain": {"extrapolation": 0}}

BOOLEAN_TEXT = {"true": True, "1": True, "false": False, "0": False}   # xs:boolean, any case


def parse_bool(text: str) -> bool:
    """``true``/``false``/``1``/``0`` (any case, spaces around) as a bool; ValueError otherwise."""
    try:
        return BOOLEAN_TEXT[str(text).strip().lower()]
    except KeyError:
        raise ValueError(f"{text!r} is not true or false") from None


_FIELDS = {f.name: f for f in fields(Settings)}


def is_list(name: str) -> bool:
    """Whether setting ``name`` takes a list of names."""
    return _FIELDS[name].metadata["form"] == "list"


def kind_of(name: str) -> type:
    """The Python type of setting ``name``'s value: float, int, str, bool or list."""
    form = _FIELDS[name].metadata["form"]
    return list if form == "list" else bool if form in ("switch", "negate", "off") else _FIELDS[name].metadata["type"]


def convert(name: str, value: object) -> object:
    """``value`` of setting ``name``: text converted through the field's type (a list from comma-separated
    names, 'none' the empty list; a bool by :func:`parse_bool`), anything else as it is."""
    if not isinstance(value, str):
        return value
    kind, text = kind_of(name), value.strip()
    if kind is list:
        return _comma_list(text)
    try:
        if kind is int:   # '20' or '2e1', not '2.5'
            number = float(text)
            if not math.isfinite(number) or number != int(number):
                raise ValueError(text)
            return int(number)
        return parse_bool(text) if kind is bool else kind(text)
    except ValueError:
        what = {bool: "true or false", float: "a number", int: "an integer"}.get(kind, "text")
        raise SettingsError(f"{name} = {value!r} is not allowed: {what}") from None


def stored_settings(attributes: dict[str, str], stop_time: float | None) -> dict[str, object]:
    """A scene's stored settings from their text (the attributes of ``cf:Settings``), typed by
    :func:`convert` and validated together as :meth:`Settings.check` does (``stop_time``: the scene's,
    for the checks against the span).  Raises :class:`SettingsError` naming the setting, its value
    and what is allowed."""
    allowed = sorted(n for n in _FIELDS if n not in NOT_STORED)
    out: dict[str, object] = {}
    for name, text in attributes.items():
        if name not in allowed:
            where = " (the scene's DefaultExperiment states it)" if name in SCENE_ONLY else ""
            raise SettingsError(f"{name} = {text!r} is not allowed as a stored setting{where}: one of "
                                f"{', '.join(allowed)}")
        out[name] = convert(name, text)
    Settings(**out, stop_time=stop_time if stop_time is not None else DEFAULT_STOP_TIME).check()
    return out
