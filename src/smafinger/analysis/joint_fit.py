"""Joint-level identification (the paper's Fig. 9): h0, h2 and C_DF from angle-vs-time curves.

Open-loop experiments on the upper (extensor) wire, the lower wire passive, each starting at rest
at the parameter set's ``theta0_deg`` with the wires at ambient; t = 0 in each file is the
moment the upper wire is switched on:

- **heating curves**: the upper wire driven from t = 0 (a voltage column, or a constant
  voltage). While it is driven the simulator uses the *heating* coefficients
  ``h0_heating, h2_heating, C_DF_heating`` and only those, so these curves identify them.
- **cooling curves**: driven for a while (a voltage column, or ``heat_s`` seconds at a
  constant voltage), then switched off; from then on the simulator uses the *cooling*
  coefficients. The heating part depends on the heating coefficients, so the fit is
  sequential: heating first, then cooling with the heating values held at their fit.

One or more curves per phase are fitted together, with the full simulator
(:func:`smafinger.simulate`, open loop). The model is nonsmooth in its parameters: the
breakaway from stiction happens on a 1 ms step, so a tiny parameter change can move it by a
step and the angle by ~0.02 deg, and branch switches and the restick add similar jumps. So no
analytic or small-step derivative is used:

1. coarse scans: a common scale factor on h (h0 and h2 together), which finds the timing
   even from a start where the model never moves within the data, then each other parameter
   on its own (a too-large M_SF can keep the joint stuck whatever h is);
2. :func:`scipy.optimize.least_squares` (trust-region reflective) with *large* central
   finite-difference steps (``diff_step`` = 1 %: secants across the jumps, not tangents of
   them). (Nelder-Mead was tried: from the same start it used its whole budget of 256 runs
   without converging, where this converges in about 80.)

Standard errors come from a 1 %-secant Jacobian in log(value) at the solution
(``s^2 (J^T J)^-1``); for a weakly identified pair (|corr(h0, h2)| > 0.99) they understate the
uncertainty, and the fit says so (``warnings``).

Identifiability of h2: h = h0 + h2 T^2 is seen only through the temperatures at which the
angle moves (the transformation bands) and the time taken to get there. h2 is identifiable when
the curves see the wire at clearly different temperatures: a *slow* heating (low voltage, so the
wire nears its steady state inside the austenite band), and *two or more* cooling curves from
different peak temperatures (different heating times). From one 8 V heating curve, or from a
single cooling curve, h0 and h2 trade off almost perfectly (docs/identification.md has numbers).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from ..engine.run import SimulationError, simulate
from ..parameters import ParameterError, ParameterSet
from ..profiles import ProfileError, VoltageProgram
from .data import AngleCurve, DataError

PHASE_FIELDS = {
    "heating": ("h0_heating_W_m2K", "h2_heating_W_m2K3", "C_DF_heating_Nms"),
    "cooling": ("h0_cooling_W_m2K", "h2_cooling_W_m2K3", "C_DF_cooling_Nms"),
}
MSF_FIELD = "M_SF_Nm"
_SHORT = {"h0_heating_W_m2K": "h0", "h2_heating_W_m2K3": "h2", "C_DF_heating_Nms": "C_DF",
          "h0_cooling_W_m2K": "h0", "h2_cooling_W_m2K3": "h2", "C_DF_cooling_Nms": "C_DF", MSF_FIELD: "M_SF"}
OUTPUT_INTERVAL_S = 0.01
DIFF_STEP = 0.01  # 1 % relative finite-difference step
SCAN_FACTORS = np.geomspace(0.25, 4.0, 9)  # common factor on h0 and h2
COORD_FACTORS = (0.25, 0.5, 2.0, 4.0)  # each other fitted parameter
MAX_RUNS = 4  # least-squares runs (restarts from the previous solution)
RESTART_TOL = 1e-4  # restart while a run lowers the SSE by more than this fraction
BAD_RESIDUAL_DEG = 180.0  # residual of a run that failed (blow-up, parameter out of range)
#: reference temperature T_a of the h parameterisation per phase [degC] (where the paper-like
#: curves pin h down best: inside the austenite band on heating, between the martensite band and
#: the peak temperature on cooling). Only the conditioning depends on it, not the optimum.
H_REF_C = {"heating": 90.0, "cooling": 110.0}
Q_MIN = 1e-6
H_CORR_WARN = 0.99  # |corr(h0, h2)| above this: warn that they are not separately identifiable
REL_SE_WARN = 0.10  # relative standard error above this: warn
OFF_BELOW_V = 0.05  # a measured voltage below this counts as off


# ---------------------------------------------------------------------------------------
# experiments
# ---------------------------------------------------------------------------------------
def program_from_voltage(curve: AngleCurve) -> VoltageProgram:
    """Piecewise-constant upper-wire program from a curve's voltage column.

    Each row's voltage holds from its time to the next row's; the first row's voltage also
    holds from t = 0. Values are rounded to 1 mV, values below :data:`OFF_BELOW_V` count as
    off (0 V), and consecutive equal values merge.
    """
    if curve.voltage_V is None:
        raise ValueError(f"{curve.path}: no voltage column")
    steps: list[tuple[float, float, float]] = []
    for k, (t, v) in enumerate(zip(curve.t_s, curve.voltage_V)):
        v = round(float(v), 3) if v >= OFF_BELOW_V else 0.0
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
    """Fit of one phase (heating or cooling) to its curves."""

    phase: str
    fields: tuple[str, ...]
    start: dict[str, float]
    values: dict[str, float]
    stderr: dict[str, float]
    rel_stderr: dict[str, float]
    correlation: list[list[float]]
    rms_deg: float
    rms_start_deg: float
    curves: list[dict]  # per curve: path, program, n_points, rms_deg
    nfev: int
    wall_s: float
    scan_factor: float
    success: bool
    message: str
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("phase", "fields", "start", "values", "stderr", "rel_stderr",
                                              "correlation", "rms_deg", "rms_start_deg", "curves", "nfev",
                                              "wall_s", "scan_factor", "success", "message", "warnings")}


class _Objective:
    """Residuals (model - data, deg) of one experiment as a function of the fit vector z.

    h = h0 + h2 T^2 is parameterised by its value at a reference temperature T_a and the share
    q of the T^2 term there: h(T) = h_a ((1 - q) + q (T/T_a)^2), i.e. h0 = h_a (1 - q),
    h2 = h_a q / T_a^2. z = (log h_a, log q, log(value/start) of the other fields). With T_a
    near the temperature the curve pins down best (:data:`H_REF_C`), log h_a and log q are far
    less correlated than log h0 and log h2 (|r| 0.5-0.8 instead of 0.96-0.997), and the box
    q <= 1 is exactly h0 >= 0.
    """

    def __init__(self, base: ParameterSet, phase: str, fields: Sequence[str], start: dict[str, float],
                 experiments: Sequence[tuple[AngleCurve, VoltageProgram]],
                 on_eval: Callable[[int], None] | None):
        self.base, self.fields, self.start = base, tuple(fields), start
        self.experiments, self.on_eval = list(experiments), on_eval
        self.data = np.concatenate([c.angle_deg for c, _ in self.experiments])
        self.n_points = int(self.data.size)
        self.Ta = H_REF_C[phase]
        self.nfev = 0
        h0, h2 = start[fields[0]], start[fields[1]]
        self.ha0 = h0 + h2 * self.Ta**2
        self.q0 = max(h2 * self.Ta**2 / self.ha0, Q_MIN)
        hi_h = _field_range(fields[0])[1]
        self.bounds = [(math.log(1e-2 / self.ha0), math.log(hi_h / self.ha0)),
                       (math.log(Q_MIN / self.q0), math.log(1.0 / self.q0))]
        for f in self.fields[2:]:
            lo, hi = _field_range(f)
            s = start[f]
            self.bounds.append((math.log(max(lo, s * 1e-3) / s), math.log(hi / s)))

    def values(self, z: np.ndarray) -> dict[str, float]:
        ha = self.ha0 * math.exp(z[0])
        q = min(self.q0 * math.exp(z[1]), 1.0)
        out = {self.fields[0]: ha * (1.0 - q), self.fields[1]: ha * q / self.Ta**2}
        for f, zi in zip(self.fields[2:], z[2:]):
            out[f] = float(self.start[f] * math.exp(zi))
        return out

    def z_of(self, values: dict[str, float]) -> np.ndarray:
        h0, h2 = values[self.fields[0]], values[self.fields[1]]
        ha = h0 + h2 * self.Ta**2
        z = [math.log(ha / self.ha0), math.log(max(h2 * self.Ta**2 / ha, Q_MIN) / self.q0)]
        z += [math.log(values[f] / self.start[f]) for f in self.fields[2:]]
        return np.array(z)

    def params(self, z: np.ndarray) -> ParameterSet:
        return self.base.replace(**self.values(z))

    def residuals_at(self, values: dict[str, float]) -> np.ndarray:
        self.nfev += 1
        try:
            p = self.base.replace(**values)
            model = np.concatenate([simulate_angle(p, prog, c.t_s) for c, prog in self.experiments])
            r = model - self.data
            if not np.all(np.isfinite(r)):
                raise SimulationError("non-finite angle")
        except (SimulationError, ParameterError, ProfileError):
            r = np.full(self.n_points, BAD_RESIDUAL_DEG)
        if self.on_eval is not None:
            self.on_eval(self.nfev)
        return r

    def residuals(self, z: np.ndarray) -> np.ndarray:
        return self.residuals_at(self.values(z))

    def sse(self, z: np.ndarray) -> float:
        r = self.residuals(z)
        return float(r @ r)


def _field_range(name: str) -> tuple[float, float]:
    from ..parameters.base import field_spec

    return field_spec(name).metadata["range"]


def fit_phase(phase: str, experiments: Sequence[tuple[AngleCurve, VoltageProgram]], base: ParameterSet,
              fit_msf: bool = False, scan: bool = True,
              on_eval: Callable[[int], None] | None = None, max_nfev: int = 40) -> PhaseFit:
    """Fit the ``phase`` coefficients (plus M_SF if ``fit_msf``) to one or more curves of that
    phase together, starting from ``base``."""
    if phase not in PHASE_FIELDS:
        raise ValueError(f"phase = {phase!r} is not one of {', '.join(PHASE_FIELDS)}")
    if not experiments:
        raise ValueError(f"no {phase} curve to fit")
    fields = PHASE_FIELDS[phase] + ((MSF_FIELD,) if fit_msf else ())
    start = {}
    for f in fields:
        v = float(getattr(base, f))
        if not (v > 0 or (f == fields[1] and v == 0)):
            raise ValueError(f"{f} = {v} in the starting set: the fit works on log(value) and needs a "
                             f"positive start")
        start[f] = v
    t0 = time.perf_counter()
    obj = _Objective(base, phase, fields, start, experiments, on_eval)
    n = obj.n_points
    z0 = np.zeros(len(fields))
    rms_start = math.sqrt(obj.sse(z0) / n)
    # 1. coarse scans: a common factor on h0 and h2 (the timing), then each other parameter on
    #    its own (q, C_DF, M_SF; a too-large M_SF can keep the joint from ever moving); again
    #    on h if anything else moved
    best = rms_start**2 * n
    best_k = 1.0
    if scan:
        if MSF_FIELD in fields:  # M_SF and h together decide when the joint breaks away
            i_msf = fields.index(MSF_FIELD)
            for m in COORD_FACTORS:
                zz = z0.copy()
                zz[i_msf] += math.log(m)
                zz, b = _scan(obj, zz, obj.sse(zz), 0, SCAN_FACTORS)
                if b < best:
                    z0, best = zz, b
        z0, best = _scan(obj, z0, best, 0, SCAN_FACTORS)
        moved = False
        for i in range(1, len(fields)):
            z0, b = _scan(obj, z0, best, i, COORD_FACTORS)
            moved = moved or b < best
            best = b
        if moved:
            z0, best = _scan(obj, z0, best, 0, SCAN_FACTORS)
        best_k = math.exp(z0[0])
    lo = np.array([b[0] for b in obj.bounds])
    hi = np.array([b[1] for b in obj.bounds])
    z0 = np.clip(z0, lo + 1e-9, hi - 1e-9)
    # 2. local fit: trust-region least squares, central differences with 1 % steps. Near the
    #    optimum the jitter of the model makes the trust region collapse early, so restart from
    #    the solution (fresh trust region) until a run no longer improves.
    z, sse = z0, best
    success, message, runs = False, "", 0
    for runs in range(1, MAX_RUNS + 1):
        res = least_squares(obj.residuals, z, bounds=(lo, hi), method="trf", jac="3-point",
                            diff_step=DIFF_STEP, x_scale=1.0, xtol=1e-8, ftol=1e-10, gtol=1e-10,
                            max_nfev=max_nfev)
        new_sse = 2.0 * float(res.cost)
        step = float(np.max(np.abs(res.x - z)))
        if new_sse <= sse:
            z, improved = res.x, sse - new_sse
            sse = new_sse
        else:
            improved = 0.0
        success, message = bool(res.success), str(res.message)
        if improved <= RESTART_TOL * sse or step < 1e-4:
            break
    # 3. uncertainty: Jacobian in log(value) with central 1 % steps (secants across the jumps)
    values = obj.values(z)
    r = obj.residuals_at(values)
    J = np.empty((r.size, len(fields)))
    for i, f in enumerate(fields):
        up, dn = dict(values), dict(values)
        up[f] = values[f] * (1 + DIFF_STEP)
        dn[f] = values[f] * (1 - DIFF_STEP)
        J[:, i] = (obj.residuals_at(up) - obj.residuals_at(dn)) / (2 * DIFF_STEP)
    dof = max(r.size - len(z), 1)
    s2 = float(r @ r) / dof
    cov = s2 * np.linalg.pinv(J.T @ J)  # of log(value): relative
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    per_curve = []
    k = 0
    for curve, prog in experiments:
        rc = r[k:k + curve.t_s.size]
        k += curve.t_s.size
        per_curve.append({"path": curve.path, "program": _program_text(prog), "n_points": int(rc.size),
                          "rms_deg": math.sqrt(float(rc @ rc) / rc.size)})
    warnings = []
    advice = ("add a slower heating curve (a lower voltage)" if phase == "heating" else
              "add a cooling curve from a different peak temperature (another heating time)")
    if abs(float(corr[0, 1])) > H_CORR_WARN:
        warnings.append(f"{phase}: h0 and h2 are not separately identifiable from these curves (correlation "
                        f"{corr[0, 1]:+.4f}); their standard errors understate the uncertainty: {advice}")
    weak = [f for i, f in enumerate(fields) if not sd[i] < REL_SE_WARN]
    if weak:
        warnings.append(f"{phase}: weakly identified (relative standard error above "
                        f"{100 * REL_SE_WARN:.0f}%): {', '.join(weak)}: {advice}")
    return PhaseFit(
        phase=phase, fields=fields, start=start, values=values,
        stderr={f: float(values[f] * sd[i]) for i, f in enumerate(fields)},
        rel_stderr={f: float(sd[i]) for i, f in enumerate(fields)},
        correlation=[[float(c) for c in row] for row in corr],
        rms_deg=math.sqrt(float(r @ r) / r.size), rms_start_deg=rms_start, curves=per_curve,
        nfev=obj.nfev, wall_s=time.perf_counter() - t0, scan_factor=best_k, success=success,
        message=f"{message} ({runs} least-squares run(s))", warnings=warnings,
    )


def _scan(obj: _Objective, z: np.ndarray, best: float, i: int, factors) -> tuple[np.ndarray, float]:
    """Try ``z[i] + log(factor)`` for each factor; keep the best (greedy)."""
    z_best = z.copy()
    for k in factors:
        if k == 1.0:
            continue
        zz = z.copy()
        zz[i] = z[i] + math.log(k)
        lo, hi = obj.bounds[i]
        if not lo <= zz[i] <= hi:
            continue
        s = obj.sse(zz)
        if s < best:
            z_best, best = zz, s
    return z_best, best


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
    experiments: dict = field(default_factory=dict, repr=False)  # phase -> [(curve, program)]

    @property
    def values(self) -> dict[str, float]:
        v = dict(self.heating.values)
        v.update(self.cooling.values)
        return v

    @property
    def warnings(self) -> list[str]:
        return self.heating.warnings + self.cooling.warnings

    def to_dict(self) -> dict:
        return {"values": self.values, "heating": self.heating.to_dict(), "cooling": self.cooling.to_dict(),
                "wall_s": self.wall_s, "fit_msf": self.fit_msf, "warnings": self.warnings}


def fit_joint(heating: Sequence[tuple[AngleCurve, VoltageProgram]],
              cooling: Sequence[tuple[AngleCurve, VoltageProgram]], base: ParameterSet,
              fit_msf: bool = False, scan: bool = True,
              on_eval: Callable[[str, int], None] | None = None, max_nfev: int = 40) -> JointFit:
    """Fit the heating coefficients on the heating curves, then the cooling ones on the cooling
    curves (heating values held at their fit). Each list holds ``(curve, program)`` pairs (see
    :func:`heating_program`, :func:`cooling_program`). ``on_eval(phase, n)`` reports progress."""
    t0 = time.perf_counter()
    cb = (lambda ph: (lambda n: on_eval(ph, n))) if on_eval is not None else (lambda ph: None)
    hf = fit_phase("heating", heating, base, fit_msf, scan, cb("heating"), max_nfev)
    mid = base.replace(**hf.values)
    cf = fit_phase("cooling", cooling, mid, False, scan, cb("cooling"), max_nfev)
    final = mid.replace(**cf.values)
    return JointFit(hf, cf, final, time.perf_counter() - t0, fit_msf,
                    {"heating": list(heating), "cooling": list(cooling)})


def phase_budget(fit_msf: bool, scan: bool = True) -> int:
    """Typical number of simulator runs of one phase (for progress bars; may be exceeded)."""
    p = 3 + (1 if fit_msf else 0)
    n_scan = len(SCAN_FACTORS) - 1 + len(COORD_FACTORS) * (p - 1) if scan else 0
    return 1 + n_scan + 20 * (2 * p + 1) + 1 + 2 * p


def joint_figure(fit: JointFit, start: ParameterSet):
    """Measured vs fitted (and starting) angle curves: heating curves on the top row, cooling
    curves below."""
    from matplotlib.figure import Figure

    ncol = max(len(fit.experiments["heating"]), len(fit.experiments["cooling"]))
    fig = Figure(figsize=(5.5 * ncol, 7.6))
    axes = fig.subplots(2, ncol, squeeze=False)
    start_cool = start.replace(**fit.heating.values)
    for row, (phase, pf, p_start) in enumerate((("heating", fit.heating, start),
                                                ("cooling", fit.cooling, start_cool))):
        exps = fit.experiments[phase]
        for j in range(ncol):
            ax = axes[row, j]
            if j >= len(exps):
                ax.set_visible(False)
                continue
            curve, prog = exps[j]
            t = np.linspace(0.0, float(curve.t_s[-1]), 1000)
            ax.plot(curve.t_s, curve.angle_deg, ".", ms=2.0, color="0.45", label="data")
            ax.plot(t, simulate_angle(p_start, prog, t), "--", color="tab:orange", lw=1, label="start")
            ax.plot(t, simulate_angle(fit.params, prog, t), "-", color="tab:blue", lw=1.5, label="fit")
            txt = ", ".join(f"{_SHORT.get(k, k)} {v:.4g}" for k, v in pf.values.items())
            ax.set_title(f"{phase}: {Path(curve.path).name} ({_program_text(prog)} V)\n{txt}\n"
                         f"RMS {pf.curves[j]['rms_deg']:.3f} deg", fontsize=8)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("angle [deg]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
