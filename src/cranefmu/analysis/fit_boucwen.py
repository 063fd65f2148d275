"""Identify the nine modified Bouc-Wen parameters (seed 001 eq. 3) from a measured rope loop.

Seed 001 identifies the parameter vector by simulation and optimisation against cyclic tensile
tests (its ref. [26]); the method is not printed.  Here: the model is simulated along the measured
elongation path (eq. 1 is rate independent, so only the path matters, see
:func:`cranefmu.physics.boucwen.simulate_path`) and ``scipy.optimize.least_squares`` minimises the
force residual.

Fitted variables (scaled to O(1) by the loop's elongation range x_r and force range F_r, k_s = F_r/x_r):
k1/k_s, k2 x_r/k_s, k3 x_r^2/k_s, c ln(b) x_r, alpha/k_s, z_u/F_r, s = gamma/beta, n, with
beta = alpha / (z_u^n (1 + s)), gamma = s beta.  This keeps every trial set admissible by simple
bounds (z_u > 0, -1 < s <= 1, n >= 1) and removes the redundancy of b and c, which enter eq. 2 only
as c ln(b): b is held at its initial value.  The initial state is z0 = F_0/F_2(x_0) - F_1(x_0) from
the first sample (clipped to the admissible band), so z0 is not a fitted variable.

The example loop ``tests/data/boucwen_loop.csv`` is made by :func:`make_example_loop`; the hoist's
loop (seed 001's rope as Table 6 states it, the set the overhead_lift scene stores) by :func:`hoist_loop`.
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import math
import sys
from dataclasses import dataclass

import numpy as np

from cranefmu.physics.boucwen import (BoucWenParams, elastic_force, for_length, shape_factor, simulate_path,
                                      z_bound)
from cranefmu.physics.params import ParameterError

MIN_ROWS = 10


class LoopFileError(ValueError):
    """A loop CSV that cannot be used (unreadable, missing columns, non-numeric, NaN, too short)."""


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit_boucwen`.

    rms: root-mean-square force error [N]; rms_relative: rms / (max force - min force) [1];
    nfev: number of loop simulations (residual evaluations, including those of the finite-difference
    Jacobian; scipy's own ``nfev`` leaves the latter out); force: fitted force at the samples [N].
    """

    params: BoucWenParams
    rms: float
    rms_relative: float
    nfev: int
    success: bool
    message: str
    force: np.ndarray


# --- files ----------------------------------------------------------------------------------

def read_loop_csv(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Elongation [m] and force [N] from a CSV with header ``elongation,force`` (extra columns ignored)."""
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as e:
        raise LoopFileError(f"{path}: cannot read the loop file: {e}") from None
    except csv.Error as e:
        raise LoopFileError(f"{path}: not a valid CSV file: {e}") from None
    numbered = [(i + 1, r) for i, r in enumerate(rows) if r and any(c.strip() for c in r)]
    if not numbered:
        raise LoopFileError(f"{path}: the file is empty; expected a header 'elongation,force' and data rows")
    header = [c.strip().lower() for c in numbered[0][1]]
    missing = [c for c in ("elongation", "force") if c not in header]
    if missing:
        raise LoopFileError(f"{path}: missing column(s) {', '.join(repr(c) for c in missing)} in the header "
                            f"{numbered[0][1]!r}; expected the header 'elongation,force' (m, N)")
    cols = {name: header.index(name) for name in ("elongation", "force")}
    data = {name: [] for name in cols}
    for line, row in numbered[1:]:
        for name, j in cols.items():
            if j >= len(row) or not row[j].strip():
                raise LoopFileError(f"{path}, line {line}: column {name!r} is empty")
            text = row[j].strip()
            try:
                value = float(text)
            except ValueError:
                raise LoopFileError(f"{path}, line {line}: column {name!r} = {text!r} is not a number") from None
            if not math.isfinite(value):
                raise LoopFileError(f"{path}, line {line}: column {name!r} = {text!r} is not finite (NaN or inf)")
            data[name].append(value)
    n = len(data["force"])
    if n < MIN_ROWS:
        raise LoopFileError(f"{path}: only {n} data row(s); a loop needs at least {MIN_ROWS}")
    x, f = np.array(data["elongation"]), np.array(data["force"])
    if np.ptp(x) == 0.0 or np.ptp(f) == 0.0:
        raise LoopFileError(f"{path}: the {'elongation' if np.ptp(x) == 0.0 else 'force'} does not vary: "
                            "not a load-unload loop")
    return x, f


def write_loop_csv(path: str, elongation: np.ndarray, force: np.ndarray) -> None:
    """Write a loop as CSV with header ``elongation,force`` (m, N)."""
    with open(path, "w", newline="") as fh:
        fh.write("elongation,force\n")
        for xv, fv in zip(elongation, force):
            fh.write(f"{xv:.9e},{fv:.9e}\n")


def synthetic_loop(p: BoucWenParams, x_max: float, cycles: int = 2, points_per_cycle: int = 120,
                   noise: float = 0.0, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A load-unload test on a virgin rope: x = x_max (1 - cos(2 pi s))/2 for s in [0, cycles] [m],
    force = rope tension of ``p`` [N] plus Gaussian noise of standard deviation ``noise`` [N]."""
    s = np.linspace(0.0, cycles, cycles * points_per_cycle + 1)
    x = 0.5 * x_max * (1.0 - np.cos(2.0 * math.pi * s))
    _, f = simulate_path(x, p)
    if noise > 0.0:
        f = f + np.random.default_rng(seed).normal(0.0, noise, f.shape)
    return x, f


def make_example_loop(path: str) -> None:
    """Write ``tests/data/boucwen_loop.csv``: the default :class:`BoucWenParams` (one 1 m line of the
    12 mm rope), two cycles 0 -> 3.8 mm -> 0 of 120 samples each (241 rows), noise 50 N
    (0.25 % of the force range), seed 1."""
    x, f = synthetic_loop(BoucWenParams(), 3.8e-3, cycles=2, points_per_cycle=120, noise=50.0, seed=1)
    write_loop_csv(path, x, f)


# seed 001 Table 6 (the hoist's rope and load) and Table 7 (the largest measured dynamic factor)
HOIST_E = 1.155e11          # E_l [Pa]
HOIST_A = 5.53e-5           # A_l [m^2]
HOIST_LINES = 4             # n_lin
HOIST_MASS = 1800.0 + 30.0  # m_2 + m_4 [kg]
HOIST_ZETA = 0.07           # zeta of eq. 9
HOIST_PEAK_FACTOR = 1.55    # Table 7, loose rope
G = 9.81


def hoist_loop(cycles: int = 3, points_per_cycle: int = 120) -> tuple[np.ndarray, np.ndarray]:
    """Load-unload loop of one 1 m line of seed 001's hoist rope, as Table 6 states that rope [m], [N].

    Seed 001 identified its Bouc-Wen set on cyclic tensile tests of a section of the 12 mm rope
    (PN-EN ISO 6892-1, its Fig. 2 and ref. [26]) and does not publish the loops or the values.  The
    nearest reproducible equivalent is the rope its Table 6 gives for the same hoist: stiffness
    E_l A_l per line and the damping of eq. 9, zeta = 0.07, which at the rope-load mode's frequency
    omega (b omega = 2 zeta c, whatever mass eq. 9 takes) dissipates a fixed fraction of the
    cycle's work.  Written along the path (eq. 1 is rate independent, so only the path matters):

        x(s) = x_m (1 - cos 2 pi s) / 2,   F(s) = k x_m / 2 (1 - cos 2 pi s + 2 zeta sin 2 pi s),  F >= 0

    with k = E_l A_l / 1 m and x_m the elongation at the largest line force of the hoist, the
    measured loose-rope factor times the suspended weight over the lines,
    F_m = 1.55 (m_2 + m_4) g / n_lin = 6957 N (Table 7; x_m = F_m / k = 1.089 mm).  The loop
    dissipates pi zeta = 22 % of its loading work k x_m^2 / 2 (derived: integral of F dx).
    """
    k = HOIST_E * HOIST_A / 1.0
    x_m = HOIST_PEAK_FACTOR * HOIST_MASS * G / HOIST_LINES / k
    th = 2.0 * math.pi * np.linspace(0.0, cycles, cycles * points_per_cycle + 1)
    x = 0.5 * x_m * (1.0 - np.cos(th))
    f = np.maximum(0.0, 0.5 * k * x_m * (1.0 - np.cos(th) + 2.0 * HOIST_ZETA * np.sin(th)))
    return x, f


# --- the fit --------------------------------------------------------------------------------

def _initial_guess(x: np.ndarray, f: np.ndarray) -> BoucWenParams:
    """A start from the loop's secant stiffness: half elastic, half hysteretic, z_u = 5 % of F_r."""
    k_s = np.ptp(f) / np.ptp(x)
    alpha = 0.5 * k_s
    zu = 0.05 * np.ptp(f)
    n = 1.0
    return BoucWenParams(k1=0.5 * k_s, k2=0.0, k3=0.0, b=2.0, c=0.0, alpha=alpha,
                         beta=0.5 * alpha / zu ** n, gamma=0.5 * alpha / zu ** n, n=n)


class _Scaling:
    """Map between BoucWenParams and the scaled fit variables (module docstring)."""

    def __init__(self, x: np.ndarray, f: np.ndarray, b: float):
        self.xr = float(np.max(np.abs(x)))
        self.fr = float(np.ptp(f))
        self.ks = self.fr / self.xr
        self.b = b
        self.lnb = math.log(b)

    def to_theta(self, p: BoucWenParams) -> np.ndarray:
        return np.array([p.k1 / self.ks, p.k2 * self.xr / self.ks, p.k3 * self.xr ** 2 / self.ks,
                         p.c * math.log(p.b) * self.xr, p.alpha / self.ks, z_bound(p) / self.fr,
                         p.gamma / p.beta, p.n])

    def to_params(self, th: np.ndarray) -> BoucWenParams:
        th = [float(v) for v in th]
        alpha = th[4] * self.ks
        zu = th[5] * self.fr
        beta = alpha / (zu ** th[7] * (1.0 + th[6]))
        return BoucWenParams(k1=th[0] * self.ks, k2=th[1] * self.ks / self.xr, k3=th[2] * self.ks / self.xr ** 2,
                             b=self.b, c=th[3] / (self.lnb * self.xr), alpha=alpha, beta=beta,
                             gamma=th[6] * beta, n=th[7])


_LOWER = np.array([0.0, 0.0, 0.0, -5.0, 1e-6, 1e-6, -0.99, 1.0])
_UPPER = np.array([np.inf, np.inf, np.inf, 5.0, np.inf, np.inf, 1.0, 10.0])


def _initial_z(x0: float, f0: float, p: BoucWenParams) -> float:
    """State that reproduces the first measured force (eq. 2 solved for z), within the admissible band."""
    if x0 <= 0.0:
        return 0.0
    zu = z_bound(p)
    z = f0 / shape_factor(x0, p) - elastic_force(x0, p)
    return min(max(z, -zu, -elastic_force(x0, p)), zu)


def simulate_loop(x: np.ndarray, f: np.ndarray, p: BoucWenParams) -> np.ndarray:
    """Rope tension [N] of ``p`` along the measured path ``x``, started from the first sample."""
    _, fm = simulate_path(x, p, z0=_initial_z(float(x[0]), float(f[0]), p))
    return fm


def fit_boucwen(elongation: np.ndarray, force: np.ndarray, initial: BoucWenParams | None = None,
                max_nfev: int = 400) -> FitResult:
    """Least-squares fit of the nine modified Bouc-Wen parameters to a measured loop.

    elongation [m], force [N]: samples in test order (the path matters, not the time).
    initial: start values (default: a guess from the loop's secant stiffness); its ``b`` is kept.
    """
    x = np.asarray(elongation, dtype=float)
    f = np.asarray(force, dtype=float)
    if x.shape != f.shape or x.ndim != 1 or len(x) < MIN_ROWS:
        raise ValueError(f"need two equally long 1-D arrays of at least {MIN_ROWS} samples, "
                         f"got shapes {x.shape} and {f.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(f))):
        raise ValueError("elongation and force must be finite")
    if np.ptp(x) == 0.0 or np.ptp(f) == 0.0:
        raise ValueError("elongation and force must vary along the loop")
    p0 = initial if initial is not None else _initial_guess(x, f)
    b = p0.b if p0.b != 1.0 else math.e  # b = 1 cannot carry a shape exponent
    p0 = dataclasses.replace(p0, b=b, c=p0.c * math.log(p0.b) / math.log(b))
    sc = _Scaling(x, f, b)
    th0 = np.clip(sc.to_theta(p0), _LOWER, _UPPER)

    count = [0]

    def residual(th: np.ndarray) -> np.ndarray:
        count[0] += 1
        try:
            p = sc.to_params(th)
        except ParameterError:
            return np.full(len(f), 1e3)
        return (simulate_loop(x, f, p) - f) / sc.fr

    from scipy.optimize import least_squares  # imported here: `cranefmu --help` should not load scipy

    # step 1e-6 of the scaled variables: well above the integrator's round-off, far below their O(1) size
    sol = least_squares(residual, th0, bounds=(_LOWER, _UPPER), method="trf", diff_step=1e-6,
                        x_scale=1.0, max_nfev=max_nfev, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    p = sc.to_params(sol.x)
    fm = simulate_loop(x, f, p)
    rms = float(np.sqrt(np.mean((fm - f) ** 2)))
    return FitResult(params=p, rms=rms, rms_relative=rms / sc.fr, nfev=count[0], success=bool(sol.success),
                     message=str(sol.message), force=fm)


# --- command line ---------------------------------------------------------------------------

def add_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Arguments of ``cranefmu fit-boucwen``."""
    parser.add_argument("loop", help="CSV file with header 'elongation,force' (m, N), samples in test order")
    parser.add_argument("--output", "-o", metavar="PARAMS.json",
                        help="write the identified parameters (and the fit error) to this JSON file")
    parser.add_argument("--sample-length", type=float, default=1.0, metavar="M",
                        help="length of the tested rope sample [m] (default 1); the parameters are "
                             "printed and written for a 1 m line, the convention of the rope FMU")
    parser.add_argument("--initial", metavar="PARAMS.json",
                        help="start values: a JSON file as written by --output (default: a guess from the loop)")
    return parser


def _params_from_json(path: str) -> BoucWenParams:
    try:
        with open(path) as fh:
            doc = json.load(fh)
        values = doc.get("parameters", doc)
        names = [name for name, _, _ in BoucWenParams.field_specs()]
        return BoucWenParams(**{k: float(values[k]) for k in names if k in values})
    except (OSError, ValueError, AttributeError, TypeError) as e:
        raise LoopFileError(f"{path}: cannot use as initial parameters: {e}") from None


def run(args: argparse.Namespace) -> int:
    """Execute ``fit-boucwen`` for parsed arguments; returns the exit code."""
    try:
        if not args.sample_length > 0.0:
            raise LoopFileError(f"--sample-length = {args.sample_length!r} m: allowed (0, inf) m")
        x, f = read_loop_csv(args.loop)
        initial = None
        if args.initial:
            # start values are given per 1 m line: bring them to the sample length
            initial = for_length(_params_from_json(args.initial), args.sample_length)
        res = fit_boucwen(x, f, initial)
    except (LoopFileError, ParameterError) as e:
        print(f"cranefmu fit-boucwen: error: {e}", file=sys.stderr)
        return 2
    p = for_length(res.params, 1.0, 1, length_ref=args.sample_length)
    print(f"modified Bouc-Wen parameters (seed 001 eq. 1-3) for one 1 m line, fitted to {args.loop}")
    for name, _, meta in BoucWenParams.field_specs():
        print(f"  {name:<6s} = {getattr(p, name): .6e}  {meta['unit']:<10s} {meta['description']}")
    print(f"  ultimate hysteretic force z_u = {z_bound(p):.6g} N")
    print(f"fit: RMS error {res.rms:.6g} N = {100.0 * res.rms_relative:.3g} % of the force range, "
          f"{res.nfev} evaluations, {'converged' if res.success else 'NOT converged'}: {res.message}")
    if args.output:
        doc = {"component": BoucWenParams.component, "model": "bouc_wen", "length_ref": 1.0,
               "parameters": {name: getattr(p, name) for name, _, _ in BoucWenParams.field_specs()},
               "units": {name: meta["unit"] for name, _, meta in BoucWenParams.field_specs()},
               "fit": {"loop": args.loop, "sample_length": args.sample_length, "rms_N": res.rms,
                       "rms_relative": res.rms_relative, "nfev": res.nfev, "success": res.success}}
        try:
            with open(args.output, "w") as fh:
                json.dump(doc, fh, indent=2)
                fh.write("\n")
        except OSError as e:
            print(f"cranefmu fit-boucwen: error: cannot write {args.output}: {e}", file=sys.stderr)
            return 2
        print(f"parameters written to {args.output}")
    return 0 if res.success else 1


def main(argv: list[str] | None = None) -> int:
    """``cranefmu fit-boucwen loop.csv [--output params.json]``."""
    parser = argparse.ArgumentParser(prog="cranefmu fit-boucwen",
                                     description="Fit the modified Bouc-Wen rope model (seed 001 eq. 1-3) "
                                                 "to a measured load-unload loop.")
    add_arguments(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
