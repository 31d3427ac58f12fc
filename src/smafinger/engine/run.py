"""Single-run API: validate the inputs, convert to SI ticks and records, call the compiled kernel."""

from __future__ import annotations

import math
import os
import threading
import time
from dataclasses import dataclass

import numpy as np

from ..control.params import ControllerParameters, controller_from
from ..control.strategies import STRATEGIES, enable_mask
from ..model.build import build_model
from ..parameters import ParameterSet, resolve
from ..plausibility import hinted
from ..progress import Display
from ..profiles import ProfileError, TargetProfile, VoltageProgram
from ..results import SimulationResult
from . import integrators, interpreted, numerics, pwm as pwm_models
from .compiled import INTERPRETED, kernels
from .kernel import Program, RunSettings, memory_stacks
from .run_inputs import check_output_grid, check_tolerance_unit, check_types
from .schedule import Segments
from .clock import TICK_S, ticks_array, to_ticks  # noqa: F401  (re-exported)
from .defaults import (DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_OUTPUT_S, DEFAULT_PWM, DEFAULT_TOL_DEG,  # noqa: F401
                       DEFAULT_TOL_M, ENGINES)
from .substep import Q_MAX, STATUS_BAD_DUTY, STATUS_OK, T_MAX_C, T_MIN_C
from .signals import MC, MECHANISM_FIELDS, METRIC_FIELDS, WIRE_FIELDS, check_recorded, every_signal, new_outputs

#: the state's physical range (:func:`.substep._finite`), as the blow-up error states it
PHYSICAL_RANGE = (f"temperatures {T_MIN_C:g} to {T_MAX_C:g} degC, the coordinate within +-{Q_MAX:g} rad or m; "
                  "stress, xi and load finite")


class SimulationError(RuntimeError):
    """The run diverged (NaN or Inf, or the state out of its physical range, :data:`PHYSICAL_RANGE`);
    the message holds the time and the state."""


class DutyNotANumber(SimulationError):
    """The closed-loop controller commanded a duty that is not a number (the run stops there)."""


@dataclass(frozen=True)
class RunSpec:
    """Everything one run needs, validated. Targets and tolerances in the mechanism's user unit."""

    params: ParameterSet
    strategy: str
    profile: TargetProfile
    voltage: VoltageProgram | None  #: the open-loop drive program (voltage, duty or current)
    t_end_s: float
    dt_s: float
    method: str
    output_interval_s: float
    tol_deg: float  #: target tolerance of the joint [deg]
    hold_s: float
    independent_wait: bool
    tol_m: float = DEFAULT_TOL_M  #: target tolerance of the linear actuator [m]
    pwm: str = DEFAULT_PWM  #: how the PWM drive is applied (engine.pwm): exact or averaged
    #: the closed-loop controller (control.params); None: the paper's PWM-PID with the set's gains
    controller: ControllerParameters | None = None

    @property
    def tolerance(self) -> float:
        """The target tolerance in the mechanism's user unit."""
        return self.tol_deg if self.params.coordinate.unit == "deg" else self.tol_m


def make_spec(params="paper2010", strategy="cooperative", profile=None, voltage=None,
              t_end_s=20.0, dt_s=None, method=None, output_interval_s=DEFAULT_OUTPUT_S,
              tol_deg=DEFAULT_TOL_DEG, hold_s=0.5, independent_wait=True, tol_m=DEFAULT_TOL_M, drive="voltage",
              pwm=None, controller=None) -> RunSpec:
    """A validated :class:`RunSpec` (see :func:`simulate` for the arguments).

    Raises ``TypeError`` for an argument of the wrong type and ``ValueError`` (or its
    subclasses ``ParameterError``, ``ProfileError``) for a bad value, in one line naming the
    argument and the value.
    """
    given = {k: v for k, v in (("dt_s", dt_s), ("method", method), ("pwm", pwm)) if v is not None}
    check_types(params=params, strategy=strategy, profile=profile, voltage=voltage, t_end_s=t_end_s,
                 output_interval_s=output_interval_s, tol_deg=tol_deg, hold_s=hold_s,
                 independent_wait=independent_wait, tol_m=tol_m, drive=drive, **given)
    p = resolve(params)
    if strategy not in STRATEGIES:
        raise ValueError(f"strategy = {strategy!r} is not one of {', '.join(STRATEGIES)}")
    if isinstance(profile, str):
        profile = TargetProfile.parse(profile)
    if isinstance(voltage, str):
        voltage = VoltageProgram.parse(voltage, drive)
    if strategy == "open-loop":
        if voltage is None:
            raise ProfileError("strategy open-loop needs a voltage program (--voltage T:V_UPPER:V_LOWER,...) "
                               "or another drive program (--duty, --current)")
        if profile is None:
            profile = TargetProfile.constant(p.initial_target, "none")
    else:
        if profile is None:
            raise ProfileError(f"strategy {strategy} needs a target profile (--profile T:TARGET[:ENABLE],...)")
        if voltage is not None:
            raise ProfileError(f"a drive program is only used with strategy open-loop, not {strategy}")
    for name, v in (("tol_deg", tol_deg), ("tol_m", tol_m), ("hold_s", hold_s)):
        if not math.isfinite(v) or v < 0:
            raise ValueError(f"{name} = {v!r} must be a finite number >= 0")
    check_tolerance_unit(p, tol_deg, tol_m)
    if controller is not None:
        controller = controller_from(controller).prepared(p)
        if strategy == "open-loop":
            raise ProfileError(f"a controller ({controller.label}) is only used in closed loop, not with open-loop")
    dt_s, method, pwm = _numerics(p, controller, t_end_s, method, dt_s, pwm, voltage)
    pwm_model = pwm_models.get(pwm)
    if integrators.get(method).pwm_sampled and pwm_model != pwm_models.PwmModel.EXACT:
        raise ValueError(f"pwm = {pwm!r} does not apply to method = {method!r}, which reads the PWM at its stages")
    spec = RunSpec(p, strategy, profile, voltage, float(t_end_s), float(dt_s), method,
                   float(output_interval_s), float(tol_deg), float(hold_s), bool(independent_wait), float(tol_m),
                   pwm, controller)
    kernel_args(spec)  # validates the times, targets and program against the mechanism
    return spec


def _numerics(p, controller, t_end_s, method, dt_s, pwm, program) -> tuple:
    """(dt_s, method, pwm): those given, else the run's default (:mod:`.numerics`)."""
    n = numerics.choose(p, controller, t_end_s, method, dt_s, pwm, program)
    return n.dt_s, n.method, n.pwm


def memory_limit_bytes() -> int:
    """The most memory one run's recorded outputs may take: half of this machine's memory
    (4 GiB where it cannot be read)."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2
    except (ValueError, OSError, AttributeError):  # pragma: no cover - platforms without sysconf
        return 4 * 2**30


def output_size(spec: RunSpec, run: RunSettings) -> tuple[int, int, int]:
    """(samples, signals, bytes) a run records; bytes counts the recorded arrays and one copy
    of them (as exporting the result makes: a table, a file)."""
    samples = run.t_end_ticks // run.out_ticks + 1
    signals = len(MECHANISM_FIELDS) + len(spec.params.wire_names) * len(WIRE_FIELDS)
    return samples, signals, 2 * 8 * samples * signals


def _check_output_size(spec: RunSpec, run: RunSettings) -> None:
    samples, signals, need = output_size(spec, run)
    limit = memory_limit_bytes()
    if need > limit:
        raise ValueError(
            f"output_interval_s = {spec.output_interval_s!r} s over t_end_s = {spec.t_end_s!r} s records "
            f"{samples:,} samples x {signals} signals, about {need / 2**30:,.1f} GiB with one copy for export: "
            f"more than the {limit / 2**30:.1f} GiB allowed (half of this machine's memory); record less "
            "often (a longer output interval) or simulate less time")


def _segments(spec: RunSpec) -> Segments:
    p = spec.params
    coord = p.coordinate
    start, target, enable = [], [], []
    for i, s in enumerate(spec.profile.segments):
        if abs(s.target) > coord.limit:
            raise ProfileError(f"profile segment {i}: target {s.target} {coord.unit} is outside "
                               f"[-{coord.limit:g}, {coord.limit:g}]")
        try:
            enable.append(enable_mask(s.enable, p.wire_names))
        except ValueError as exc:
            raise ProfileError(f"profile segment {i}: {exc}") from None
        start.append(-1 if s.start_s is None else to_ticks("profile start", s.start_s, True))
        target.append(p.to_si(s.target))
    return Segments(np.array(start, dtype=np.int64), np.array(target), np.array(enable, dtype=np.int64))


def _program(spec: RunSpec, model) -> Program:
    p = spec.params
    n = len(p.wire_names)
    prog = spec.voltage
    if prog is None:
        return Program(np.zeros(0, dtype=np.int64), np.zeros((0, n)), np.zeros((0, n)))
    if prog.n_wires != n:
        raise ProfileError(f"{prog.kind} program: {prog.n_wires} value(s) per step, but a {p.mechanism} has "
                           f"{n} wire(s) ({', '.join(p.wire_names)})")
    cols = prog.arrays()
    values = np.column_stack(cols[1:])
    if prog.kind == "duty":
        level, duty = np.full_like(values, p.V_H_V), 100.0 * values
    else:
        level, duty = values, np.where(values > 0.0, 100.0, 0.0)
    directions = np.array([w.direction for w in model.wires])
    both = ((duty > 0) & (level > 0) & (directions > 0)).any(axis=1) & ((duty > 0) & (level > 0) & (directions < 0)).any(axis=1)
    if both.any():
        i = int(np.flatnonzero(both)[0])
        raise ProfileError(f"{prog.kind} program step {i} (t = {cols[0][i]} s): both wires heated at once "
                           f"({', '.join(f'{v:g}' for v in values[i])}) would break the interlock")
    return Program(ticks_array(f"{prog.kind} start", cols[0]), level, duty)


def kernel_args(spec: RunSpec, record: str = "all") -> dict:
    """The records and arrays the kernel takes (validated); ``record``: see :func:`run_spec`."""
    t_end = to_ticks("t_end_s", spec.t_end_s)
    dt = to_ticks("dt_s", spec.dt_s)
    if dt > t_end:
        raise ValueError(f"dt_s = {spec.dt_s} is longer than t_end_s = {spec.t_end_s}")
    p = spec.params
    integ = integrators.get(spec.method)
    run = RunSettings(
        strategy=STRATEGIES[spec.strategy], method=integ.code,
        wait_release=spec.independent_wait,
        current_drive=spec.voltage is not None and spec.voltage.kind == "current",
        tick_s=TICK_S, dt_ticks=dt, t_end_ticks=t_end,
        out_ticks=to_ticks("output_interval_s", spec.output_interval_s),
        update_ticks=to_ticks("controller_update_s", p.controller_update_s, allow_zero=True),
        pwm_ticks=to_ticks("pwm_period_s", p.pwm_period_s),
        tol=p.to_si(spec.tolerance), hold_ticks=to_ticks("hold_s", spec.hold_s, True),
        pwm=pwm_models.PwmModel.SAMPLED if integ.pwm_sampled else pwm_models.get(spec.pwm),
        every_signal=every_signal(record))
    check_output_grid(spec, run)
    _check_output_size(spec, run)
    model = build_model(p)
    if spec.controller is not None:
        model = model._replace(controller=spec.controller.record(p, model.controller))
    return dict(model=model, run=run, segs=_segments(spec), prog=_program(spec, model))


def _prepared(spec: RunSpec, args: dict | None = None, samples: int | None = None) -> tuple:
    """(kernel arguments, kernel key, outputs, segment starts and reaches); ``samples=1``: arguments
    of the same types without the run's outputs allocated (to look the kernel up)."""
    args = kernel_args(spec) if args is None else args
    n = args["run"].t_end_ticks // args["run"].out_ticks + 1 if samples is None else samples
    mech, wires = new_outputs(n, len(spec.params.wire_names))
    seg_actual = np.full(len(spec.profile.segments), -1, dtype=np.int64)
    seg_reached = seg_actual.copy()
    call_args = (args["model"], args["run"], args["segs"], args["prog"], mech, wires, seg_actual, seg_reached,
                 memory_stacks(wires.shape[1]))
    key = (spec.params.mechanism, len(spec.params.wire_names), type(args["model"].controller))
    return call_args, key, mech, wires, seg_actual, seg_reached


def kernel_key(spec: RunSpec) -> tuple:
    """What the compiled kernel depends on: the mechanism, the wire count, the controller's record type."""
    return _prepared(spec, samples=1)[1]


def kernel_cached(spec: RunSpec, args: dict | None = None) -> bool:
    """Whether the kernel ``spec`` needs is loaded here or in numba's disk cache (no compile)."""
    probe, key = _prepared(spec, args, samples=1)[:2]  # the outputs' types, not their size
    return kernels.cached(key, probe)


def compile_kernel(spec: RunSpec) -> None:
    """Compile the kernel ``spec`` needs (or load it from numba's cache), without running it."""
    call_args, key = _prepared(spec, samples=1)[:2]
    kernels(key, call_args)


def run_spec(spec: RunSpec, progress=False, engine="compiled", record="all") -> SimulationResult:
    """Run one validated spec; returns a :class:`~smafinger.results.SimulationResult`.

    ``progress``: ``True`` shows a bar on a terminal (plain lines otherwise), or give a
    :class:`smafinger.progress.Display` (even one that shows nothing: the run then goes on in
    a thread, so that Ctrl-C is answered at once). ``engine``: see :mod:`.interpreted`.
    ``record``: ``"all"`` signals, or (compiled) only those its metrics read (``"metrics"``,
    :data:`.signals.METRIC_FIELDS`: the same metrics; the result has only those signals)."""
    if engine not in ENGINES:
        raise ValueError(f"engine = {engine!r} is not one of {', '.join(ENGINES)}")
    args = kernel_args(spec, record)
    if engine != "compiled" and not INTERPRETED:
        if interpreted.choose(engine, kernel_cached(spec, args), spec) == "interpreted":
            if engine == "interpreted":
                return interpreted.run_interpreted(spec)
            interpreted.build_in_background(spec)
            try:
                return interpreted.run_interpreted(spec)
            except interpreted.InterpretedFailure:
                pass  # auto: compile here instead
    call_args, key, mech, wires, seg_actual, seg_reached = _prepared(spec, args)
    kernel = kernels(key, call_args)  # compiles outside the timing
    t0 = time.perf_counter()
    if progress is True or isinstance(progress, Display):
        counters, state, t_fail = _run_with_progress(lambda: kernel(*call_args), mech, spec.t_end_s, progress)
    else:
        counters, state, t_fail = kernel(*call_args)
    wall = time.perf_counter() - t0
    if counters.status == STATUS_BAD_DUTY:
        raise DutyNotANumber(f"the controller commanded a duty that is not a number at t = {t_fail:.9g} s "
                              f"(controller {spec.controller.label if spec.controller else 'pid'!r}; does it "
                              f"read a sensor it does not declare?): {describe_state(spec.params, state)}")
    if counters.status != STATUS_OK:
        raise SimulationError(f"numerical blow-up at t = {t_fail:.9g} s (a value NaN or infinite, or the state "
                              f"out of any physical range: {PHYSICAL_RANGE}): {describe_state(spec.params, state)}")
    check_recorded(mech)
    return SimulationResult(
        spec=spec, mechanism_signals=mech, wire_signals=wires, segment_start_s=np.where(seg_actual >= 0, seg_actual * TICK_S, np.nan),
        segment_reached_s=np.where(seg_reached >= 0, (seg_reached - seg_actual) * TICK_S, np.nan),
        substeps=int(counters.substeps), interlock_violations=int(counters.violations), wall_s=wall,
        engine="interpreted" if INTERPRETED else "compiled",
        recorded=None if args["run"].every_signal else METRIC_FIELDS)


def describe_state(p: ParameterSet, state) -> str:
    """The state, every value named (for error messages)."""
    si = "rad" if p.mechanism == "joint" else "m"
    coord, rate = (("theta", "omega"), ("position", "velocity"))[p.mechanism != "joint"]
    parts = [f"{coord}_{si}={state.q:.6g}", f"{rate}_{si}_s={state.v:.6g}",
             f"error_integral={state.error_integral:.6g}"]
    for name, w in zip(p.wire_names, state.wires):
        parts += [f"T_{name}_C={w.T_C:.6g}", f"sigma_{name}_Pa={w.sigma_Pa:.6g}",
                  f"electrical_energy_{name}_J={w.electrical_J:.6g}", f"T_casing_{name}_C={w.T_case_C:.6g}"]
    return ", ".join(parts)


def _run_with_progress(call, mech, t_end_s, progress):
    """Run the (nogil) kernel in a thread and show its progress from the output rows.

    ``progress``: ``True`` (a bar on a terminal, plain lines otherwise) or a
    :class:`smafinger.progress.Display`. The calling thread only waits, so Ctrl-C stops the
    wait at once (the compiled loop cannot be interrupted: its daemon thread is left to end
    with the process).
    """
    display = progress if isinstance(progress, Display) else Display.auto(True)
    box = []
    th = threading.Thread(target=lambda: box.append(call()), daemon=True)
    task = display.task("simulating", t_end_s, "s", integer=False)
    try:
        th.start()
        while th.is_alive():
            th.join(0.1)
            done = mech[MC.t]
            filled = done[~np.isnan(done)]
            task.update(completed=float(filled[-1]) if filled.size else 0.0)
    finally:
        if display is not progress:
            display.stop()
    return box[0]


def simulate(params="paper2010", strategy="cooperative", profile=None, voltage=None, t_end_s=20.0,
             dt_s=None, method=None, output_interval_s=DEFAULT_OUTPUT_S, tol_deg=DEFAULT_TOL_DEG,
             hold_s=0.5, independent_wait=True, progress=False, tol_m=DEFAULT_TOL_M, drive="voltage",
             pwm=None, controller=None, engine=None, check_step=False):
    """Simulate an SMA wire actuator (the paper's finger joint or the linear bias-spring rig).

    Parameters
    ----------
    params : str, path or ParameterSet
        A named set (``paper2010``, ``authors2020``, ``linear-bias-spring``, ...), a TOML file,
        or a set. The set's mechanism decides the units of targets and outputs.
    strategy : {"open-loop", "independent", "cooperative"}
    profile : str or TargetProfile
        Target schedule ``"T:TARGET[:ENABLE],..."`` (seconds; degrees for the joint, metres for
        the linear actuator; ``reach`` as T starts a segment when the previous target is reached).
    voltage : str or VoltageProgram
        Open-loop program ``"T:V_1[:V_2],..."``: one value per wire (upper, lower for the joint),
        read as ``drive`` says.
    drive : {"voltage", "duty", "current"}
        How a text ``voltage`` program is read: volts, fractions of the supply V_H (switched at
        the PWM period), or amperes.
    t_end_s, output_interval_s : float
        Simulated time and output sampling interval [s] (whole nanoseconds).
    dt_s, method, pwm : optional
        The numerics: integration step [s]; fixed-step integrator (``"rk4"``, ``"euler"``,
        ``"semi-implicit"``, ``"exponential"``, ``"authors-ode4"``: the authors' Simulink
        solver, RK4 with the PWM read at its stages; :mod:`.integrators`); the PWM drive
        resolved at its edges (``"exact"``) or its period-averaged power (``"averaged"``,
        valid when the PWM period is far below the wire's thermal time constant; :mod:`.pwm`).
        None of them given: the fastest setting validated for the run (:mod:`.numerics`: a
        long step of 5 ms with the PWM averaged, else the joint's edge step with it exact, else
        rk4, 1 ms, exact; docs/speed.md). Any of them given: the others from rk4, 1 ms, exact.
    tol_deg, tol_m, hold_s : float
        A target counts as reached once within ``tol_deg`` (joint) or ``tol_m`` (linear
        actuator) for ``hold_s``.
    independent_wait : bool
        Independent strategy: wait for the previous agonist's cooling phase to end before
        using the other actuator (Sec. 4.1).
    controller : str or ControllerParameters, optional
        The closed-loop controller (:mod:`smafinger.control.params`: ``pid``, ``fuzzy-pid``,
        ``sliding-mode``, ``rapid-heating``, ``resistance``); default the paper's PWM-PID.
    engine : {"auto", "compiled", "interpreted"}, optional
        Default ``$SMAFINGER_ENGINE``, else ``auto``: the compiled kernel if cached, else a
        short run interpreted (the same equations in plain Python; 1.2 s for the 45 s cycle)
        while the kernel compiles in the background (:mod:`.interpreted`).
    progress : bool or smafinger.progress.Display
        Show the simulated time as the run goes (a terminal's progress bar).
    check_step : bool
        Run it again at half the step and compare (:mod:`smafinger.step_check`): the result's
        ``step_check``, and a warning among its metrics' if the error estimated from the
        difference is over the budget. ``smafinger simulate`` does this by default on a slider
        and on a finger-joint set changed from a named one (docs/cli.md, "The step check").
        Under ``engine="auto"`` the check runs on the engine the run used.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ParameterError, ProfileError, ValueError, TypeError
        Bad input, before anything runs; the message names the argument or field and the value.
    SimulationError
        The state became NaN or Inf (a numerical blow-up), with the time, the state and what to
        change (the step, the method, a parameter that looks extreme;
        :func:`~smafinger.plausibility.blowup_hint`); :class:`DutyNotANumber` if the controller
        commanded a duty that is no number.
    """
    spec = make_spec(params, strategy, profile, voltage, t_end_s, dt_s, method, output_interval_s,
                     tol_deg, hold_s, independent_wait, tol_m, drive, pwm, controller)
    if not isinstance(check_step, (bool, np.bool_)):
        raise TypeError(f"check_step = {check_step!r} is not True or False")
    if check_step:
        from ..step_check import half_step

        half_step(spec)  # a step with no shorter one is refused before the run
    setting = interpreted.engine_setting(engine)
    result = hinted(spec, lambda: run_spec(spec, progress=progress, engine=setting), style="api")
    if check_step:  # asked for: made, however long interpreted
        from ..step_check import API_REMEDY, check_engine, with_step_check

        result = with_step_check(result, check_engine(result, setting, skip_long=False), remedy=API_REMEDY)
    return result
