"""Joint-level identification (the paper's Fig. 9): h0, h2 and C_DF from angle-vs-time curves.

Two open-loop experiments on the upper (extensor) wire, the lower wire passive, both starting
at rest at the parameter set's ``theta0_deg`` with the wires at ambient; t = 0 in each file is the
moment the upper wire is switched on:

- **heating curve**: the upper wire driven from t = 0 (a voltage column, or ``voltage_V``
  constant). While it is driven the simulator uses the *heating* coefficients
  ``h0_heating, h2_heating, C_DF_heating`` (and only those), so this curve identifies them.
- **cooling curve**: driven for ``heat_s`` seconds (a voltage column, or ``heat_s``), then
  switched off; after that the simulator uses the *cooling* coefficients. Its heating part
  depends on the heating coefficients, so the fit is sequential: heating first, then cooling
  with the heating values held at their fit.

Each phase is fitted with the full simulator (:func:`smafinger.simulate`, open loop). The model
is nonsmooth in its parameters (stick/slip onset, kinetics branch switches and the fixed-step
clock make the angle jump by small amounts under tiny parameter changes), so no analytic or
small-step derivative is used:

1. a coarse scan of a common scale factor on h (h0 and h2 together), which finds the right
   timing even from a start where the model never moves;
2. :func:`scipy.optimize.least_squares` (trust-region reflective) on ``log(value/start)`` with a
   *large* finite-difference step (``diff_step`` = 1 %: a secant across the jumps, not a
   tangent of them); optionally Nelder-Mead (``method="nelder-mead"``), derivative-free.

Standard errors come from the 1 %-secant Jacobian at the solution (``s^2 (J^T J)^-1``).

Identifiability of h2: h = h0 + h2 T^2 is only seen through the temperatures the angle
reveals (the transformation bands). h2 is identifiable when the curves span two different
temperature regions: a *slow* heating (a low voltage, so that the wire approaches its steady
state inside the austenite band) and a cooling that starts well above the martensite band
(a long or strong heating first). At 8 V the heating curve alone leaves h0 and h2 almost
perfectly correlated (|r| > 0.99); see docs/identification.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares, minimize

from ..engine.run import SimulationError, simulate
from ..parameters import ParameterError, ParameterSet
from ..profiles import ProfileError, VoltageProgram
from .data import AngleCurve, DataError

PHASE_FIELDS = {
    "heating": ("h0_heating_W_m2K", "h2_heating_W_m2K3", "C_DF_heating_Nms"),
    "cooling": ("h0_cooling_W_m2K", "h2_cooling_W_m2K3", "C_DF_cooling_Nms"),
}
MSF_FIELD = "M_SF_Nm"
OUTPUT_INTERVAL_S = 0.01
DIFF_STEP = 0.01  # 1 % relative finite-difference step
SCAN_FACTORS = np.geomspace(0.25, 4.0, 9)
BAD_RESIDUAL_DEG = 180.0  # residual of a run that failed (blow-up, parameter out of range)


# ---------------------------------------------------------------------------------------
# experiments
# ---------------------------------------------------------------------------------------
def program_from_voltage(curve: AngleCurve) -> VoltageProgram:
    """Piecewise-constant upper-wire program from a curve's voltage column.

    Each row's voltage holds from its time to the next row's; the first row's voltage also
    holds from t = 0. Values are rounded to 1 mV; consecutive equal values merge.
    """
    if curve.voltage_V is None:
        raise ValueError(f"{curve.path}: no voltage column")
    steps: list[tuple[float, float, float]] = []
    for k, (t, v) in enumerate(zip(curve.t_s, curve.voltage_V)):
        v = round(float(v), 3)
        t0 = 0.0 if k == 0 else round(float(t), 9)
        if not steps or v != steps[-1][1]:
            steps.append((t0, v, 0.0))
    return VoltageProgram(tuple(steps))


def heating_program(curve: AngleCurve, voltage_V: float) -> VoltageProgram:
    """The heating experiment's program: the voltage column, else ``voltage_V`` from t = 0."""
    if curve.voltage_V is not None:
        return program_from_voltage(curve)
    return VoltageProgram(((0.0, float(voltage_V), 0.0),))


def cooling_program(curve: AngleCurve, voltage_V: float, heat_s: float | None) -> VoltageProgram:
    """The cooling experiment's program: ``heat_s`` if given (``voltage_V`` from 0 to
    ``heat_s``, then 0 V), else the file's voltage column. Raises ValueError if neither."""
    if heat_s is not None:
        if not (math.isfinite(heat_s) and heat_s > 0):
            raise ValueError(f"heat_s = {heat_s!r}: the heating time must be a positive number of seconds")
        if heat_s >= curve.t_s[-1]:
            raise ValueError(f"heat_s = {heat_s:g} s is not before the end of the cooling curve "
                             f"{curve.path} ({curve.t_s[-1]:g} s)")
        return VoltageProgram(((0.0, float(voltage_V), 0.0), (round(float(heat_s), 9), 0.0, 0.0)))
    if curve.voltage_V is not None:
        prog = program_from_voltage(curve)
        if prog.steps[-1][1] != 0.0:
            raise DataError(f"{curve.path}: row {len(curve.t_s)}: the voltage column never returns to 0 V, "
                            f"so this is not a cooling curve")
        return prog
    raise ValueError(f"{curve.path} has no voltage column: give the heating time before the voltage "
                     f"was switched off (--heat-s)")


def _t_end(t_last: float) -> float:
    n = math.ceil(t_last / OUTPUT_INTERVAL_S - 1e-9) + 1
    return round(n * OUTPUT_INTERVAL_S, 9)


def simulate_angle(params: ParameterSet, program: VoltageProgram, t_s: np.ndarray) -> np.ndarray:
    """Model joint angle [deg] at the times ``t_s`` under an open-loop program."""
    r = simulate(params, strategy="open-loop", voltage=program, t_end_s=_t_end(float(t_s[-1])),
                 output_interval_s=OUTPUT_INTERVAL_S)
    return np.interp(t_s, r.t, r.theta_deg)


def synthesize(params: ParameterSet, program: VoltageProgram | str, t_end_s: float,
               sample_s: float = 0.05, noise_deg: float = 0.0, seed: int = 0,
               path: str = "<synthetic>") -> AngleCurve:
    """A synthetic measured curve: the model's angle every ``sample_s`` plus Gaussian noise."""
    if isinstance(program, str):
        program = VoltageProgram.parse(program)
    n = int(round(t_end_s / sample_s))
    t = np.round(np.arange(n + 1) * sample_s, 9)
    th = simulate_angle(params, program, t)
    rng = np.random.default_rng(seed)
    th = th + noise_deg * rng.standard_normal(th.shape)
    # the voltage each row sees (upper wire)
    starts = np.array([s[0] for s in program.steps])
    vu = np.array([s[1] for s in program.steps])
    v = vu[np.searchsorted(starts, t, side="right") - 1]
    return AngleCurve(path, t, th, v)


# ---------------------------------------------------------------------------------------
# fitting one phase
# ---------------------------------------------------------------------------------------
@dataclass
class PhaseFit:
    """Fit of one experiment (heating or cooling)."""

    phase: str
    fields: tuple[str, ...]
    start: dict[str, float]
    values: dict[str, float]
    stderr: dict[str, float]
    rel_stderr: dict[str, float]
    correlation: list[list[float]]
    rms_deg: float
    rms_start_deg: float
    nfev: int
    wall_s: float
    program: str
    path: str
    scan_factor: float
    success: bool
    message: str

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("phase", "path", "program", "start", "values", "stderr",
                                              "rel_stderr", "correlation", "rms_deg", "rms_start_deg",
                                              "nfev", "wall_s", "scan_factor", "success", "message")}


class _Objective:
    """Residuals (model - data, deg) of one experiment as a function of log(value/start)."""

    def __init__(self, base: ParameterSet, fields: Sequence[str], start: dict[str, float],
                 curve: AngleCurve, program: VoltageProgram, on_eval: Callable[[int], None] | None):
        self.base, self.fields, self.start = base, tuple(fields), start
        self.curve, self.program, self.on_eval = curve, program, on_eval
        self.nfev = 0
        self.bounds = []
        for f in self.fields:
            lo, hi = _field_range(f)
            s = start[f]
            self.bounds.append((math.log(max(lo, s * 1e-3) / s), math.log(hi / s)))

    def values(self, z: np.ndarray) -> dict[str, float]:
        return {f: float(self.start[f] * math.exp(zi)) for f, zi in zip(self.fields, z)}

    def params(self, z: np.ndarray) -> ParameterSet:
        return self.base.replace(**self.values(z))

    def residuals(self, z: np.ndarray) -> np.ndarray:
        self.nfev += 1
        try:
            model = simulate_angle(self.params(z), self.program, self.curve.t_s)
            r = model - self.curve.angle_deg
            if not np.all(np.isfinite(r)):
                raise SimulationError("non-finite angle")
        except (SimulationError, ParameterError, ProfileError):
            r = np.full(self.curve.t_s.shape, BAD_RESIDUAL_DEG)
        if self.on_eval is not None:
            self.on_eval(self.nfev)
        return r

    def sse(self, z: np.ndarray) -> float:
        r = self.residuals(z)
        return float(r @ r)


def _field_range(name: str) -> tuple[float, float]:
    from ..parameters.base import field_spec

    return field_spec(name).metadata["range"]


def fit_phase(phase: str, curve: AngleCurve, program: VoltageProgram, base: ParameterSet,
              fit_msf: bool = False, method: str = "least-squares", scan: bool = True,
              on_eval: Callable[[int], None] | None = None, max_nfev: int = 80) -> PhaseFit:
    """Fit the ``phase`` coefficients (plus M_SF if ``fit_msf``) to one curve, from ``base``."""
    if phase not in PHASE_FIELDS:
        raise ValueError(f"phase = {phase!r} is not one of {', '.join(PHASE_FIELDS)}")
    fields = PHASE_FIELDS[phase] + ((MSF_FIELD,) if fit_msf else ())
    start = {}
    for f in fields:
        v = float(getattr(base, f))
        if not v > 0:
            lo, hi = _field_range(f)
            raise ValueError(f"{f} = {v} in the starting set: the fit works on log(value) and needs a "
                             f"positive start")
        start[f] = v
    t0 = time.perf_counter()
    obj = _Objective(base, fields, start, curve, program, on_eval)
    z0 = np.zeros(len(fields))
    rms_start = math.sqrt(obj.sse(z0) / curve.t_s.size)
    # 1. coarse scan of a common factor on h0 and h2 (the timing), C_DF and M_SF held
    best_k, best = 1.0, rms_start**2 * curve.t_s.size
    if scan:
        for k in SCAN_FACTORS:
            if k == 1.0:
                continue
            z = z0.copy()
            z[0] = z[1] = math.log(k)
            s = obj.sse(z)
            if s < best:
                best_k, best = float(k), s
    z0[0] = z0[1] = math.log(best_k)
    lo = np.array([b[0] for b in obj.bounds])
    hi = np.array([b[1] for b in obj.bounds])
    z0 = np.clip(z0, lo + 1e-9, hi - 1e-9)
    # 2. local fit
    if method == "least-squares":
        res = least_squares(obj.residuals, z0, bounds=(lo, hi), method="trf", diff_step=DIFF_STEP,
                            x_scale=1.0, xtol=1e-4, ftol=1e-6, gtol=1e-8, max_nfev=max_nfev)
        z, success, message = res.x, bool(res.success), str(res.message)
    elif method == "nelder-mead":
        simplex = np.vstack([z0] + [z0 + 0.2 * np.eye(len(z0))[i] for i in range(len(z0))])
        res = minimize(obj.sse, z0, method="Nelder-Mead", bounds=list(zip(lo, hi)),
                       options={"initial_simplex": np.clip(simplex, lo, hi), "xatol": 1e-4,
                                "fatol": 1e-9, "maxfev": max_nfev * 4, "adaptive": True})
        z, success, message = res.x, bool(res.success), str(res.message)
    else:
        raise ValueError(f"method = {method!r} is not one of least-squares, nelder-mead")
    # 3. uncertainty from the 1 %-secant Jacobian at the solution (central differences)
    r = obj.residuals(z)
    J = np.empty((r.size, len(z)))
    for i in range(len(z)):
        dz = np.zeros(len(z))
        dz[i] = DIFF_STEP
        J[:, i] = (obj.residuals(z + dz) - obj.residuals(z - dz)) / (2 * DIFF_STEP)
    dof = max(r.size - len(z), 1)
    s2 = float(r @ r) / dof
    cov = s2 * np.linalg.pinv(J.T @ J)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    values = obj.values(z)
    return PhaseFit(
        phase=phase, fields=fields, start=start, values=values,
        stderr={f: values[f] * sd[i] for i, f in enumerate(fields)},  # d value = value d log(value)
        rel_stderr={f: float(sd[i]) for i, f in enumerate(fields)},
        correlation=[[float(c) if np.isfinite(c) else 0.0 for c in row] for row in corr],
        rms_deg=math.sqrt(float(r @ r) / r.size), rms_start_deg=rms_start, nfev=obj.nfev,
        wall_s=time.perf_counter() - t0, program=_program_text(program), path=curve.path,
        scan_factor=best_k, success=success, message=message,
    )


def _program_text(p: VoltageProgram) -> str:
    return ",".join(f"{t:g}:{u:g}:{l:g}" for t, u, l in p.steps)


# ---------------------------------------------------------------------------------------
# both phases
# ---------------------------------------------------------------------------------------
@dataclass
class JointFit:
    heating: PhaseFit
    cooling: PhaseFit
    params: ParameterSet  # base with all fitted values
    wall_s: float
    fit_msf: bool
    method: str
    curves: dict = field(default_factory=dict, repr=False)  # phase -> (curve, program)

    @property
    def values(self) -> dict[str, float]:
        v = dict(self.heating.values)
        v.update(self.cooling.values)
        return v

    def to_dict(self) -> dict:
        return {"values": self.values, "heating": self.heating.to_dict(), "cooling": self.cooling.to_dict(),
                "wall_s": self.wall_s, "fit_msf": self.fit_msf, "method": self.method}


def fit_joint(heating: AngleCurve, cooling: AngleCurve, base: ParameterSet,
              heating_prog: VoltageProgram, cooling_prog: VoltageProgram, fit_msf: bool = False,
              method: str = "least-squares", scan: bool = True,
              on_eval: Callable[[str, int], None] | None = None, max_nfev: int = 80) -> JointFit:
    """Fit the heating coefficients on the heating curve, then the cooling ones on the cooling
    curve (heating values held at their fit). ``on_eval(phase, n)`` reports progress."""
    t0 = time.perf_counter()
    cb = (lambda ph: (lambda n: on_eval(ph, n))) if on_eval is not None else (lambda ph: None)
    hf = fit_phase("heating", heating, heating_prog, base, fit_msf, method, scan, cb("heating"), max_nfev)
    mid = base.replace(**hf.values)
    cf = fit_phase("cooling", cooling, cooling_prog, mid, False, method, scan, cb("cooling"), max_nfev)
    final = mid.replace(**cf.values)
    return JointFit(hf, cf, final, time.perf_counter() - t0, fit_msf, method,
                    {"heating": (heating, heating_prog), "cooling": (cooling, cooling_prog)})


def phase_budget(fit_msf: bool, max_nfev: int = 80, scan: bool = True) -> int:
    """Upper bound on the simulator runs of one phase (for progress bars)."""
    p = 3 + (1 if fit_msf else 0)
    return 1 + (len(SCAN_FACTORS) - 1 if scan else 0) + max_nfev * (p + 1) + 1 + 2 * p


def plot_joint(path: str | Path, fit: JointFit, start: ParameterSet) -> None:
    """Measured vs fitted (and starting) angle curves, heating and cooling side by side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..results import atomic_write

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    start_cool = start.replace(**fit.heating.values)
    for ax, phase, pf, p_start in ((axes[0], "heating", fit.heating, start),
                                   (axes[1], "cooling", fit.cooling, start_cool)):
        curve, prog = fit.curves[phase]
        t = np.linspace(0.0, float(curve.t_s[-1]), 1000)
        ax.plot(curve.t_s, curve.angle_deg, ".", ms=2.5, color="0.45", label="data")
        ax.plot(t, simulate_angle(p_start, prog, t), "--", color="tab:orange", lw=1, label="start")
        ax.plot(t, simulate_angle(fit.params, prog, t), "-", color="tab:blue", lw=1.5, label="fit")
        txt = ", ".join(f"{k.split('_')[0]} {v:.4g}" for k, v in pf.values.items())
        ax.set_title(f"{phase}: {Path(curve.path).name}\n{txt}; RMS {pf.rms_deg:.3f} deg", fontsize=9)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("angle [deg]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format=Path(path).suffix.lstrip(".") or "png"))
    plt.close(fig)
