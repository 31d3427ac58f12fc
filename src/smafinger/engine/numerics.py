"""A run's numerical settings (integrator, step, PWM model): the ones given, or the run's default.

A run that sets none of ``dt_s``, ``method`` and ``pwm`` gets the fastest setting that was
validated for it against a run at a far shorter step with exact PWM edges:

- :data:`LONG_STEP`, exponential Euler, 5 ms, period-averaged PWM, on the finger joint: with
  the rate-form stress law in closed and in open loop, with the algebraic law (the authors' 2020
  model) in open loop;
- :data:`LONG_STEP_STIFF` on a slider pulled directly by the wire (the linear bias-spring rig,
  algebraic law): semi-implicit Euler with the wire's stiffness implicit too
  (:func:`.integrators.implicit_load`), 5 ms, period-averaged PWM: a setting to give, no run's
  default (:func:`long_step_refusal`: the slider's momentum after a drive change);
- :data:`EDGE_STEP` on the finger joint where only the average is the trouble (a hysteresis
  rule that follows the PWM ripple, a PWM period longer than the step, the authors' 2020 model in
  closed loop, the rapid-heating controller, a controller at gains other than the ones the long
  step was validated with): exponential Euler with the PWM
  resolved at its edges, so a sub-step ends at every edge and output sample, as with the
  reference, but costs one right-hand side instead of four;
- the reference settings (RK4, 1 ms, exact PWM) everywhere else; on a slider, RK4's step is
  shortened to hold the wire-slider mode (:func:`reference_dt`). The reference itself is not
  validated on every rig: on a light, lightly damped slider it can be over the budget
  (docs/speed.md, "The linear rig"), which ``smafinger simulate`` checks after the run by
  default there (:mod:`smafinger.step_check`).

A run that sets any of the three gets the reference values for the others, as before the
long-step default existed. Where each holds and why it does not elsewhere: docs/speed.md.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from ..parameters.options import Hysteresis, JouleHeating, StressLaw
from .defaults import (DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_PWM, LONG_STEP_DT_S, LONG_STEP_METHOD,
                       LONG_STEP_PWM, LONG_STEP_STIFF_METHOD)
from .stability import REAL_AXIS, UNDAMPED

#: the long step needs at least this many steps across the transformation band (A_S0 to A_F0)
#: at the run's strongest drive (:func:`_fast_transformation`). Measured on the linear rig in
#: open loop, full duty for seconds, then cooling through the return to martensite, against RK4
#: at 0.1 ms (position RMS / max over the 18 mm stroke, peak stress; with the stiffness at the
#: wires the step leaves, :func:`.integrators.implicit_load`, since 0a71aa2): 45.5 steps (the
#: validated program's strongest drive) 0.008 / 0.047 mm; 25.5 steps (12 V) 0.015 / 0.087;
#: 13.8 (16 V) 0.021 / 0.23; 12.2 (a 0.5 m wire at 50 %) 0.011 / 0.15; 8.6 (20 V) 0.028 / 0.77,
#: over the budget (0.05 / 0.6 mm), 50 against 48 MPa; 5.9 (24 V) a false trajectory, the slider
#: at its end stop, 839 against 122 MPa (found by review), and 2.1 (a 0.3 m wire at 12 V) 426
#: against 233 MPa. Kept at 20, where it was set before that change; it decides for the joint
#: (the rig's long step is refused anyway). The paper's and the authors' sets at their drives:
#: 266 and 230 steps.
MIN_BAND_STEPS = 20


@dataclass(frozen=True)
class Numerics:
    method: str
    dt_s: float
    pwm: str


REFERENCE = Numerics(DEFAULT_METHOD, DEFAULT_DT_S, DEFAULT_PWM)
LONG_STEP = Numerics(LONG_STEP_METHOD, LONG_STEP_DT_S, LONG_STEP_PWM)
#: the slider's long step: with the algebraic law its wire's stress follows the position at
#: once, and the wire's axial stiffness against the slider's mass is a fast, barely damped mode
#: (omega = sqrt(kappa) = 527 rad/s on the linear rig at rest, kappa from implicit_load) that no
#: explicit update of the position holds: exponential Euler gave 8.4 mm RMS at 1 ms and 1.5 mm
#: at 0.1 ms against rk4, symplectic Euler (semi-implicit without kappa) held 2 ms, not 5 ms.
#: On the joint the series tendon spring and the joint's damping leave exponential Euler
#: better (authors2020's mechanics with the memory rule, open loop, against rk4 at 10 us: 0.0128
#: deg RMS, 0.063 max against semi-implicit's 0.0146, 0.062; 0.028, 0.108 before 0a71aa2)
LONG_STEP_STIFF = Numerics(LONG_STEP_STIFF_METHOD, LONG_STEP_DT_S, LONG_STEP_PWM)
#: the joint's integrator and step with the PWM resolved at its edges (:func:`edge_step_refusal`)
EDGE_STEP = Numerics(LONG_STEP_METHOD, LONG_STEP_DT_S, DEFAULT_PWM)
#: the closed-loop controllers the long step was validated with (None: the paper's PID).
#: sliding-mode (benchmarks/bench_defaults.py): at its defaults, the bench's tuning, a 0.01 rad/s
#: boundary layer and K 50 %, on the full cycle co-operative and independent, and a scheduled
#: profile on paper2010-table2, 7 runs within 0.026 deg RMS and 0.16 max of rk4 at 0.1 ms.
#: rapid-heating is not: 0.059 deg RMS, 0.41 max on the co-operative full cycle
LONG_STEP_CONTROLLERS = ("pid", "sliding-mode")
#: the sets whose own PID gains the long step was validated with in closed loop (every paper2010
#: scenario). With other gains the period-averaged PWM can put reach times off by tenths of a
#: second where the joint creeps into the tolerance band: on the full cycle co-operative against
#: rk4 at 0.1 ms (benchmarks/bench_defaults.py), the bench's pid-tuned gains (K_P 2365, K_V 1311,
#: K_I 13.65) gave 0.37 deg RMS, 2.3 deg max, and K_V 300 2.2 deg RMS, 11.9 max, against 0.031 /
#: 0.19 and 0.025 / 0.088 at the edge step
LONG_STEP_GAINS_OF = ("paper2010",)
#: the PID gains of a joint set, named as in the set (per rad)
GAIN_FIELDS = ("K_P_per_rad", "K_V_s_per_rad", "K_I_per_rad_s")
#: the closed-loop controllers the edge step was validated with (None: the paper's PID).
#: fuzzy-pid: 0.106 deg RMS, 0.49 max on the co-operative full cycle (rk4 at 1 ms: 0.018, 0.083);
#: resistance: its loop hunts, rk4 at 1 ms is 0.18 deg RMS, 1.1 max from rk4 at 0.1 ms itself
EDGE_STEP_CONTROLLERS = LONG_STEP_CONTROLLERS + ("rapid-heating",)


def long_step(params) -> Numerics:
    """The long-step setting of a parameter set's mechanism (module docstring)."""
    return LONG_STEP if params.mechanism == "joint" else LONG_STEP_STIFF


def _shorter_than_the_step(t_end_s: float) -> str | None:
    if not t_end_s >= LONG_STEP_DT_S:
        return f"t_end_s = {t_end_s:g} is shorter than the long step ({LONG_STEP_DT_S:g} s)"
    return None


def long_step_refusal(params, controller, t_end_s: float, program=None) -> str | None:
    """Why no long-step setting is this run's default (None: :func:`long_step` is).

    Validated (benchmarks/bench_speed.py, tests/test_numerics.py) for:

    - the rate-form stress law: the finger joint (every paper2010 scenario within 0.066 deg RMS
      of a 0.1 ms RK4 run, the full cycle 0.0047 deg), per-metre Joule heating (``whole-wire``
      heating of ``paper2010-table2`` gave 1.2 deg RMS, 6.7 deg max at the long step), the
      paper's PWM-PID or the sliding-mode controller (``controller`` None or one of
      :data:`LONG_STEP_CONTROLLERS`, a prepared
      :class:`~smafinger.control.params.ControllerParameters`) at the set's own gains, those of
      :data:`LONG_STEP_GAINS_OF` (:func:`_other_gains`; other gains get the edge step), or
      open loop;
    - the algebraic stress law in open loop on the finger joint: the authors' 2020 joint with
      the memory rule (0.013 deg RMS). Not on the linear rig, whose slider's momentum matters
      (found by a random search of 2,910 rig runs, 231 over the budget of 0.05 mm RMS, 0.6 mm
      max; docs/speed.md): the wire against the slider's mass is a mode of 500-900 rad/s on the
      template, and a drive cut while the wire transforms lets the slider coast on for about
      1/omega, unloading the wire, which transforms further, and the memory rule keeps it. The
      long step damps that mode (the template, full duty cut at 0.65 s: 0.83 mm max, 0.22 mm
      RMS over 40 s; semi-implicit at 0.1 ms still 0.16 mm max; rk4 at 1 ms 0.003 mm). Fast cooling
      (h0_cooling 600 W/m^2K: 0.73 mm max), static friction of 0.8 N (0.77 mm max) and a start
      off the major loop fail too. Through the wire's return to martensite its long step holds
      since 0a71aa2 (its program run to 45 s: 0.008 mm RMS, 0.047 mm max; it was 0.13, 0.91).
      Not in closed loop: on the linear rig the closed loop's reach times scatter by seconds
      between step sizes (RK4 at 0.1 ms against 1 us included), so no step can be checked
      against a converged run;
    - either law: the return-point-memory hysteresis and a PWM period no longer than the step
      (the average then covers whole periods). An open-loop ``program``
      (:class:`~smafinger.profiles.VoltageProgram`; None in closed loop) may switch at any rate:
      steps end at its switches, and with the wires moved at the mechanism's mean rate over a
      step (:mod:`.integrators`) an 80 % square wave stayed within the budget against rk4 at
      0.1 ms for periods from 2 s down to 5-50 ms: at 8 V on paper2010 0.008 deg RMS, 0.06 deg
      max; on the authors' joint with the memory rule 0.0093 / 0.072 deg (with the algebraic
      law a program's steps had to be 0.5 s apart until 0a71aa2, a rule set on the linear rig);
    - a transformation that takes :data:`MIN_BAND_STEPS` long steps or more at the run's
      strongest drive (:func:`_fast_transformation`).
    """
    opts = params.options
    if (short := _shorter_than_the_step(t_end_s)) is not None:
        return short
    if opts.hysteresis != Hysteresis.MEMORY:
        return f"hysteresis {opts.hysteresis.label}: its branch follows the PWM ripple the average removes"
    if opts.stress_law == StressLaw.ALGEBRAIC:
        if params.mechanism != "joint":
            return (f"mechanism {params.mechanism} with the algebraic stress law: the long step damps the "
                    "wire-slider mode that carries the slider on after a drive change (0.83 mm max on the template; "
                    "docs/speed.md)")
        if program is None:
            return ("the algebraic stress law in closed loop: not validated (on the linear rig its reach times scatter "
                    "by seconds between step sizes)")
    else:
        if params.mechanism != "joint":
            return f"mechanism {params.mechanism} with the rate law: not validated at long steps"
        if opts.joule_heating != JouleHeating.PER_METRE:
            return (f"joule_heating {opts.joule_heating.label}: not validated at long steps (1.2 deg RMS on the "
                    "full cycle)")
        if controller is not None and controller.label not in LONG_STEP_CONTROLLERS:
            return f"controller {controller.label}: not validated at long steps"
        if program is None and (other := _other_gains(params, controller)) is not None:
            return other
    if params.pwm_period_s > LONG_STEP_DT_S:
        return f"pwm_period_s = {params.pwm_period_s:g} is longer than the long step ({LONG_STEP_DT_S:g} s)"
    if (fast := _fast_transformation(params, program)) is not None:
        return fast
    return None


def _strongest_drive(params, program) -> tuple[float, bool]:
    """(the strongest drive a wire of the run gets, as its period's root mean square
    (:func:`.pwm.averaged_drive`, with the low level V_L between pulses) [V or A]; whether it is
    a current): in closed loop V_H or V_L (any duty from 0 to 100 %), in open loop the program's
    strongest step or V_L (a duty program's steps are fractions of V_H; a current's low level is
    0 A). The low level counted too (found by review: V_L = 16 V took the long step where 16 V
    pulses at full duty did not)."""
    from .pwm import averaged_drive

    averaged_drive = getattr(averaged_drive, "py_func", averaged_drive)  # not compiled for this
    low = params.V_L_V
    if program is None:
        return max(params.V_H_V, low), False
    values = np.column_stack(program.arrays()[1:])
    if program.kind == "duty":
        return max(averaged_drive(params.V_H_V, low, 100.0 * float(d)) for d in np.unique(values)), False
    if program.kind == "current":
        return float(values.max()), True
    return max(float(values.max()), low), False


def _fast_transformation(params, program) -> str | None:
    """Why the transformation is too fast for the long step (None: it is not): the wire heats
    across its band A_S0 to A_F0 in fewer than :data:`MIN_BAND_STEPS` long steps at the run's
    strongest drive (Eq. 11 at A_S0 with the heating coefficients, no radiation: its fastest
    heating there)."""
    from ..model import heat
    from ..model.build import build_model

    def plain(f):  # the compiled function's Python body: called here, it is not compiled (0.6 s a record type)
        return getattr(f, "py_func", f)

    drive, current = _strongest_drive(params, program)
    model = build_model(params)
    wire = model.wires[0]  # every wire has the set's thermal fields
    T = params.A_S0_C  # Eq. (11) there, the heating coefficients, to the ambient (radiation, if any, left out)
    P = plain(heat.joule_power_per_m)(wire, drive, current, model.options.joule_heating)
    h = plain(heat.convection_coefficient)(T, wire.h0_heating_W_m2K, wire.h2_heating_W_m2K3)
    rate = plain(heat.heat_balance)(T, P, h, wire.T_amb_C, wire.mass_per_length_kg_m, wire.specific_heat_J_kgK,
                                    wire.perimeter_m)
    band = params.A_F0_C - params.A_S0_C
    if rate > 0.0 and band < MIN_BAND_STEPS * LONG_STEP_DT_S * rate:
        unit = "A" if current else "V"
        return (f"the wire crosses its transformation band ({params.A_S0_C:g} to {params.A_F0_C:g} degC) in "
                f"{1e3 * band / rate:.3g} ms at its strongest drive ({drive:.4g} {unit}: {rate:.4g} degC/s), fewer "
                f"than {MIN_BAND_STEPS} long steps of {1e3 * LONG_STEP_DT_S:g} ms")
    return None


@functools.cache
def _validated_gains() -> frozenset:
    """The gains of :data:`LONG_STEP_GAINS_OF` (built once: a set costs about 0.1 ms)."""
    from ..parameters import get

    return frozenset(tuple(getattr(get(name), f) for f in GAIN_FIELDS) for name in LONG_STEP_GAINS_OF)


def _other_gains(params, controller) -> str | None:
    """Why the closed loop's gains are not those the long step was validated with (None: they are).

    Validated: the controller with every field at its default (derived from the set), on a set
    whose PID gains are those of one of :data:`LONG_STEP_GAINS_OF`.
    """
    given = [] if controller is None else [f.name for f in dataclasses.fields(controller)
                                           if "range" in f.metadata and getattr(controller, f.name) != f.default]
    if given:
        return (f"controller {controller.label} with {', '.join(given)} given: the long step was validated with "
                "the set's own gains only")
    gains = tuple(getattr(params, f) for f in GAIN_FIELDS)
    if gains not in _validated_gains():
        return (f"PID gains {', '.join(f'{f} = {g:g}' for f, g in zip(GAIN_FIELDS, gains))}: the long step was "
                f"validated with those of {', '.join(LONG_STEP_GAINS_OF)} only")
    return None


def edge_step_refusal(params, controller, t_end_s: float) -> str | None:
    """Why :data:`EDGE_STEP` is not this run's default when the long step is refused (None: it is).

    Validated (benchmarks/bench_defaults.py, tests/test_numerics.py, docs/speed.md) against RK4
    at 0.1 ms on the finger joint with per-metre Joule heating, under any hysteresis rule, stress
    law, PWM period and program, in open loop and with the controllers of
    :data:`EDGE_STEP_CONTROLLERS`: the 20 runs of the benchmark that get it are within 0.037 deg
    RMS and 0.28 deg max (the reference: 0.035 and 0.31), 1.7-3.0x faster than the reference
    (median 2.2x): the authors' 2020 model with its own rule (profiles 1 and
    2, the full cycle co-operative and independent, a program, rapid-heating and sliding-mode
    control; within 0.0094 and 0.087) and with the memory rule (the full cycle, the worst);
    paper2010 with their rule or the dead-band one, PWM periods of 10 to 50 ms, rapid-heating
    control at its defaults and the bench's tuning. Whole-wire heating is not:
    its closed loop does not converge (RK4 at 0.1 ms is 0.076 deg RMS, 0.74 max from 10 us on
    the full cycle).
    """
    if (short := _shorter_than_the_step(t_end_s)) is not None:
        return short
    if params.mechanism != "joint":
        return f"mechanism {params.mechanism}: not validated with the PWM resolved at long steps"
    if params.options.joule_heating != JouleHeating.PER_METRE:
        return (f"joule_heating {params.options.joule_heating.label}: not validated (its full cycle does not converge "
                "with the step, RK4 included)")
    if controller is not None and controller.label not in EDGE_STEP_CONTROLLERS:
        return f"controller {controller.label}: not validated with the PWM resolved at long steps"
    return None


#: the reference's RK4 takes at most this many radians of the wire-slider mode a step
#: (:func:`reference_dt`): the template rig in austenite is 0.90 at 1 ms, where a drive cut
#: while the wire transforms is within 0.003 mm of rk4 at 0.1 ms
WIRE_MODE_RAD_PER_STEP = 1.0
#: and at most this much of the damping's rate (lambda h, :func:`damping_rate_per_s`): RK4 is
#: stable up to 2.785 (.stability.REAL_AXIS); the paper's cooling damping at 1 ms is 1.84, which
#: the golden record and the convergence tests hold. A random search of the joint at the
#: reference (whole-wire heating) blew up in 48 of 83 runs with lambda h above 2.785 at 1 ms and
#: in none of 284 below it
DAMPING_PER_STEP = 2.0
#: the damping shortens the reference's step down to this [s] (1 ms / 100), no further: a set
#: damped beyond it (200,000 1/s: 100 times the paper's) keeps 1 ms, and its blow-up names the
#: extreme parameter (plausibility.blowup_hint) rather than running 10^8 steps in silence
DAMPED_STEP_MIN_S = 1e-5


def damping_rate_per_s(params) -> float:
    """The mechanism's stiffest real mode, its viscous damping over its inertia [1/s]: C_DF / I of
    Eq. (2) for the joint (the larger of heating and cooling), c / m for the slider."""
    if params.mechanism == "joint":
        return max(params.C_DF_heating_Nms, params.C_DF_cooling_Nms) / params.inertia_kg_m2
    return params.viscous_damping_N_s_m / params.slider_mass_kg


def wire_mode_omega(params) -> float | None:
    """omega [rad/s] of the wire against the slider's mass at its stiffest, in austenite:
    sqrt((D_A A_w / L_w + K_bias) / m). A slider pulled directly by its wire has this fast,
    barely damped mode (904 rad/s on the template rig; 5,700 on a 0.1 m wire pulling 5 g).
    None on the finger joint, where the series tendon spring and the joint's inertia and damping
    keep the fastest mode the damping's (-C_DF/I, about 1.5 ms for RK4)."""
    if params.mechanism == "joint":
        return None
    area = math.pi * params.wire_diameter_m ** 2 / 4.0
    return math.sqrt((params.D_A_Pa * area / params.wire_length_m + params.bias_spring_K_N_m) / params.slider_mass_kg)


def damping_step_limit(params, method: str) -> float | None:
    """The longest step [s] an explicit ``method`` holds against the damping's rate
    (:func:`damping_rate_per_s`, by :data:`.stability.REAL_AXIS`); None for a method exact in the
    damping (exponential, semi-implicit) or a set with none."""
    bound, rate = REAL_AXIS.get(method), damping_rate_per_s(params)
    return None if bound is None or rate <= 0.0 else bound / rate


def reference_dt(params) -> float:
    """The reference's step [s]: 1 ms, or where a mode is too fast for RK4 at 1 ms the longest
    1 ms / n (n dividing 10^6, so that the step is a whole number of nanoseconds) that holds it:
    a slider's wire-slider mode turning at most :data:`WIRE_MODE_RAD_PER_STEP` a step (RK4 at 1 ms
    went unstable there and, held by the end stops, returned a wrong trajectory: a 0.1 m wire
    pulling 5 g, 5,700 rad/s, was 19 mm RMS off rk4 at 10 us over a 1.8 mm stroke), and the
    damping at most :data:`DAMPING_PER_STEP`, down to :data:`DAMPED_STEP_MIN_S` (a joint with 5
    times the paper's heating damping blew up at 1 ms)."""
    omega = wire_mode_omega(params) or 0.0
    rate = damping_rate_per_s(params)
    if rate * DAMPED_STEP_MIN_S > DAMPING_PER_STEP:
        rate = 0.0  # beyond any step this shortens to: 1 ms, and a blow-up that says why

    def holds(h: float) -> bool:
        return omega * h <= WIRE_MODE_RAD_PER_STEP and rate * h <= DAMPING_PER_STEP

    # 1 ns at most: a mode beyond that is refused (unstable_step) or blows up with the step named
    return DEFAULT_DT_S / next((n for n in _DIVISORS_OF_1MS if holds(DEFAULT_DT_S / n)), _DIVISORS_OF_1MS[-1])


#: the fields the modes :func:`reference_dt` holds grow with (+1) or fall with (-1): the
#: wire-slider mode's omega (:func:`wire_mode_omega`) and the damping's rate (:func:`damping_rate_per_s`)
_STIFFNESS_FIELDS = {"D_A_Pa": 1, "wire_diameter_m": 1, "bias_spring_K_N_m": 1, "wire_length_m": -1, "slider_mass_kg": -1,
                     "viscous_damping_N_s_m": 1, "C_DF_heating_Nms": 1, "C_DF_cooling_Nms": 1, "inertia_kg_m2": -1}


def reference_dt_within(params, bounds) -> float:
    """:func:`reference_dt` of the stiffest set within ``bounds`` (field name -> (lo, hi), the
    others as in ``params``): one step that holds every set a fit may try. A freed slider mass
    or wire had candidates beyond the start set's step, each refused and scored as a miss."""
    stiffest = {name: bounds[name][1 if sign > 0 else 0] for name, sign in _STIFFNESS_FIELDS.items() if name in bounds}
    return reference_dt(params.replace(**stiffest) if stiffest else params)


#: the divisors of 10^6 (1 ms in nanoseconds), ascending
_DIVISORS_OF_1MS = tuple(sorted(2 ** i * 5 ** j for i in range(7) for j in range(7)))


def unstable_step(params, method: str, dt_s: float, advice: bool = True) -> str | None:
    """Why a method's step cannot hold the run's wire-slider mode (None: it can, or the
    mechanism has none), by :data:`.stability.UNDAMPED`: RK4 and the authors' solver beyond
    h omega = 2 sqrt(2); Euler and exponential Euler (exact in the damping, explicit in the
    wire's stiffness) beyond h omega^2 = c, the viscous damping over the mass (they amplify a
    mode damped less than that at every step: exponential Euler on the template at 0.1 ms was
    1.15 mm RMS, 2.3 mm max off with no warning). Such a run does not blow up: the end stops hold
    the slider, and the result is wrong (found by review). ``semi-implicit`` takes the stiffness
    implicitly: any step."""
    omega = wire_mode_omega(params)
    bound = UNDAMPED.get(method)
    if omega is None or bound is None:
        return None
    c = params.viscous_damping_N_s_m / params.slider_mass_kg
    limit = bound / omega if bound > 0.0 else c / omega ** 2
    if dt_s <= limit:
        return None
    why = (f"dt_s = {dt_s:g} is beyond {method}'s stability limit for this slider's wire-slider mode "
           f"(omega = {omega:.4g} rad/s, the wire in austenite against the slider's mass)")
    return f"{why}: use dt_s <= {limit:.3g} or method semi-implicit" if advice else why


def chosen(params, controller, t_end_s: float, method: str | None, dt_s: float | None,
           pwm: str | None, program=None) -> Numerics:
    """The numerics a run with these settings gets: the given values, else the run's default
    (module docstring); unchecked (a sweep's base set records them, but is no run itself)."""
    if method is None and dt_s is None and pwm is None:
        if long_step_refusal(params, controller, t_end_s, program) is None:
            return long_step(params)
        if edge_step_refusal(params, controller, t_end_s) is None:
            return EDGE_STEP
    return Numerics(REFERENCE.method if method is None else method,
                    reference_dt(params) if dt_s is None else dt_s,
                    REFERENCE.pwm if pwm is None else pwm)


def choose(params, controller, t_end_s: float, method: str | None, dt_s: float | None,
           pwm: str | None, program=None) -> Numerics:
    """The run's numerics (:func:`chosen`). Raises ``ValueError`` for a step the run's
    wire-slider mode makes unstable (:func:`unstable_step`)."""
    n = chosen(params, controller, t_end_s, method, dt_s, pwm, program)
    if (why := unstable_step(params, n.method, n.dt_s)) is not None:
        raise ValueError(why if dt_s is not None else f"{why} (dt_s not given: the reference's step on this slider)")
    return n
