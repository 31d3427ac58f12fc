"""Single-run API: validate the inputs, convert to SI ticks, call the compiled kernel."""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass

import numpy as np

from ..control.strategies import ENABLES, STRATEGIES
from ..model.layout import pack
from ..parameters import ParameterSet, resolve
from ..profiles import ProfileError, TargetProfile, VoltageProgram
from . import integrators
from .kernel import C_STATUS, C_SUBSTEPS, C_VIOLATIONS, N_COUNTERS, N_OUT, STATUS_BLOWUP, run_kernel
from .rhs import N_STATE

TICK_S = 1e-9
DEFAULT_DT_S = 1e-3
#: classical RK4. Forward Euler at 1 ms is about 3x faster on the co-operative full cycle and
#: 0.01 deg RMS from a 1 us reference there (benchmarks/bench_core.py), but it blows up on
#: the open-loop Table II runs of Figs. 7-8 (a stiff joint-tendon mode): not a safe default.
DEFAULT_METHOD = "rk4"
DEFAULT_OUTPUT_S = 1e-3
STATE_NAMES = ("theta_rad", "omega_rad_s", "T_upper_C", "T_lower_C", "sigma_upper_Pa",
               "sigma_lower_Pa", "error_integral_rad_s", "E_upper_J", "E_lower_J")


class SimulationError(RuntimeError):
    """The run diverged (NaN or Inf); the message holds the time and the state."""


def to_ticks(name: str, value_s: float, allow_zero: bool = False) -> int:
    """Seconds to integer ticks of 1 ns; refuses values that are not whole ticks."""
    if not isinstance(value_s, (int, float)) or not math.isfinite(value_s):
        raise ValueError(f"{name} = {value_s!r} is not a finite number of seconds")
    if value_s < 0 or (value_s == 0 and not allow_zero):
        raise ValueError(f"{name} = {value_s!r} s must be {'>= 0' if allow_zero else '> 0'}")
    ticks = round(value_s / TICK_S)
    if abs(ticks * TICK_S - value_s) > 1e-6 * TICK_S * max(1.0, ticks) and abs(ticks * TICK_S - value_s) > 1e-12:
        raise ValueError(f"{name} = {value_s!r} s is not a whole number of nanoseconds")
    return int(ticks)


def ticks_array(name: str, values_s: np.ndarray) -> np.ndarray:
    """:func:`to_ticks` (zero allowed) of many times at once; the first bad one is named."""
    v = np.asarray(values_s, dtype=float)
    ticks = np.rint(v / TICK_S)
    err = np.abs(ticks * TICK_S - v)
    ok = (np.isfinite(v) & (v >= 0)
          & ((err <= 1e-6 * TICK_S * np.maximum(1.0, ticks)) | (err <= 1e-12)))
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        to_ticks(f"{name} [{i}]", float(v[i]), allow_zero=True)  # raises with the reason
    return ticks.astype(np.int64)


@dataclass(frozen=True)
class RunSpec:
    """Everything one run needs, validated and in kernel form."""

    params: ParameterSet
    strategy: str
    profile: TargetProfile
    voltage: VoltageProgram | None
    t_end_s: float
    dt_s: float
    method: str
    output_interval_s: float
    tol_deg: float
    hold_s: float
    independent_wait: bool


def make_spec(params="paper2010", strategy="cooperative", profile=None, voltage=None,
              t_end_s=20.0, dt_s=DEFAULT_DT_S, method=DEFAULT_METHOD, output_interval_s=DEFAULT_OUTPUT_S,
              tol_deg=0.5, hold_s=0.5, independent_wait=True) -> RunSpec:
    p = resolve(params)
    if strategy not in STRATEGIES:
        raise ValueError(f"strategy = {strategy!r} is not one of {', '.join(STRATEGIES)}")
    integrators.get(method)
    if isinstance(profile, str):
        profile = TargetProfile.parse(profile)
    if isinstance(voltage, str):
        voltage = VoltageProgram.parse(voltage)
    if strategy == "open-loop":
        if voltage is None:
            raise ProfileError("strategy open-loop needs a voltage program (--voltage T:V_UPPER:V_LOWER,...)")
        if profile is None:
            profile = TargetProfile.constant(p.theta0_deg, "none")
    else:
        if profile is None:
            raise ProfileError(f"strategy {strategy} needs a target profile (--profile T:ANGLE[:ENABLE],...)")
        if voltage is not None:
            raise ProfileError(f"a voltage program is only used with strategy open-loop, not {strategy}")
    for name, v in (("tol_deg", tol_deg), ("hold_s", hold_s)):
        if not math.isfinite(v) or v < 0:
            raise ValueError(f"{name} = {v!r} must be a finite number >= 0")
    spec = RunSpec(p, strategy, profile, voltage, float(t_end_s), float(dt_s), method,
                   float(output_interval_s), float(tol_deg), float(hold_s), bool(independent_wait))
    kernel_args(spec)  # validates the times
    return spec


def kernel_args(spec: RunSpec) -> dict:
    """The plain arrays and integers the kernel takes."""
    t_end = to_ticks("t_end_s", spec.t_end_s)
    dt = to_ticks("dt_s", spec.dt_s)
    out = to_ticks("output_interval_s", spec.output_interval_s)
    pwm = to_ticks("pwm_period_s", spec.params.pwm_period_s)
    upd = to_ticks("controller_update_s", spec.params.controller_update_s, allow_zero=True)
    if dt > t_end:
        raise ValueError(f"dt_s = {spec.dt_s} is longer than t_end_s = {spec.t_end_s}")
    segs = spec.profile.segments
    seg_start = np.array([-1 if s.start_s is None else to_ticks("profile start", s.start_s, True) for s in segs], dtype=np.int64)
    seg_target = np.array([math.radians(s.target_deg) for s in segs])
    seg_enable = np.array([ENABLES[s.enable] for s in segs], dtype=np.int64)
    if spec.voltage is not None:
        vs, vu, vl = spec.voltage.arrays()
        vt = ticks_array("voltage start", vs)
    else:
        vt = np.zeros(0, dtype=np.int64)
        vu = np.zeros(0)
        vl = np.zeros(0)
    return dict(
        p=pack(spec.params), seg_start=seg_start, seg_target=seg_target, seg_enable=seg_enable,
        strategy=STRATEGIES[spec.strategy], wait_release=spec.independent_wait,
        volt_ticks=vt, volt_u=vu, volt_l=vl, method=integrators.get(spec.method).code,
        dt_ticks=dt, tick_s=TICK_S, t_end_ticks=t_end, out_ticks=out, update_ticks=upd,
        pwm_ticks=pwm, tol_rad=math.radians(spec.tol_deg), hold_ticks=to_ticks("hold_s", spec.hold_s, True),
    )


def run_spec(spec: RunSpec, progress: bool = False):
    """Run one validated spec; returns a :class:`~smafinger.results.SimulationResult`."""
    from ..results import SimulationResult

    args = kernel_args(spec)
    n_out = args["t_end_ticks"] // args["out_ticks"] + 1
    out = np.full((n_out, N_OUT), np.nan)
    seg_actual = np.full(len(spec.profile.segments), -1, dtype=np.int64)
    seg_reached = np.full(len(spec.profile.segments), -1, dtype=np.int64)
    counters = np.zeros(N_COUNTERS + 1, dtype=np.int64)
    err = np.zeros(1 + N_STATE)
    call = lambda: run_kernel(out=out, seg_actual=seg_actual, seg_reached=seg_reached, counters=counters, err_state=err, **args)  # noqa: E731
    if not run_kernel.signatures:
        # compile (or load from the cache) on a one-step run, so wall_s times the loop alone
        warm = dict(args, t_end_ticks=args["dt_ticks"], out_ticks=args["dt_ticks"])
        run_kernel(out=np.full((2, N_OUT), np.nan), seg_actual=seg_actual.copy(), seg_reached=seg_reached.copy(),
                   counters=np.zeros_like(counters), err_state=np.zeros_like(err), **warm)
    t0 = time.perf_counter()
    if progress:
        _run_with_progress(call, out, spec.t_end_s)
    else:
        call()
    wall = time.perf_counter() - t0
    if counters[C_STATUS] == STATUS_BLOWUP:
        state = ", ".join(f"{n}={v:.6g}" for n, v in zip(STATE_NAMES, err[1:]))
        raise SimulationError(f"numerical blow-up at t = {err[0]:.9g} s: {state}")
    return SimulationResult(
        spec=spec, data=out, segment_start_s=seg_actual * TICK_S,
        segment_reached_s=np.where(seg_reached >= 0, (seg_reached - seg_actual) * TICK_S, np.nan), substeps=int(counters[C_SUBSTEPS]),
        interlock_violations=int(counters[C_VIOLATIONS]), wall_s=wall,
    )


def _run_with_progress(call, out, t_end_s):
    """Run the (nogil) kernel in a thread and show its progress from the output rows."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    th = threading.Thread(target=call)
    with Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.completed:.1f}/{task.total:.1f} s"),
                  TimeRemainingColumn(), transient=True) as bar:
        task = bar.add_task("sim", total=t_end_s)
        th.start()
        while th.is_alive():
            th.join(0.1)
            done = out[:, 0]
            filled = done[~np.isnan(done)]
            bar.update(task, completed=float(filled[-1]) if filled.size else 0.0)


def simulate(params="paper2010", strategy="cooperative", profile=None, voltage=None, t_end_s=20.0,
             dt_s=DEFAULT_DT_S, method=DEFAULT_METHOD, output_interval_s=DEFAULT_OUTPUT_S, tol_deg=0.5,
             hold_s=0.5, independent_wait=True, progress=False):
    """Simulate the finger joint.

    Parameters
    ----------
    params : str, path or ParameterSet
        A named set (``paper2010``, ``authors2020``, ...), a TOML file, or a set.
    strategy : {"open-loop", "independent", "cooperative"}
    profile : str or TargetProfile
        Target schedule ``"T:ANGLE[:ENABLE],..."`` (degrees, seconds; ``reach`` as T starts a
        segment when the previous target is reached).
    voltage : str or VoltageProgram
        Open-loop program ``"T:V_UPPER:V_LOWER,..."``.
    t_end_s, dt_s, output_interval_s : float
        Simulated time, step and output sampling interval [s] (whole nanoseconds).
    method : {"rk4", "euler"}
        Fixed-step integrator (default :data:`DEFAULT_METHOD`, rk4).
    tol_deg, hold_s : float
        A target counts as reached once within ``tol_deg`` for ``hold_s``.
    independent_wait : bool
        Independent strategy: wait for the previous agonist's cooling phase to end before
        using the other actuator (Sec. 4.1).

    Returns
    -------
    SimulationResult
    """
    spec = make_spec(params, strategy, profile, voltage, t_end_s, dt_s, method, output_interval_s,
                     tol_deg, hold_s, independent_wait)
    return run_spec(spec, progress=progress)
