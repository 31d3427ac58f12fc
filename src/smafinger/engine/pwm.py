"""How the engine applies the PWM drive of Eq. (12b): resolved, period-averaged or sampled.

Each wire sees ``level`` (V_H, or a program's level) for the first t_DC = t_P DC%/100 of every
PWM period t_P and ``low`` (V_L) for the rest (Fig. 6). Three ways to put that into the model:

- ``exact``: the drive is switched at every period start and duty edge; the engine ends a
  sub-step there, so each sub-step sees a constant drive (valid always; the default).
- ``averaged``: over a step, each wire sees the period-averaged drive: the level whose square is
  the mean square of the PWM wave, sqrt(d level^2 + (1 - d) low^2), d = DC%/100. Joule heat is
  proportional to the drive's square (Eq. 11: V^2 / R_w, or I^2 R_w), so the heat, and the
  electrical energy, delivered per period are exact; what is lost is the temperature ripple
  within a period. Valid when t_P is far below the wire's thermal time constant
  M_w C_p / (h A_w): for the paper's wire 9.6 s at ``paper2010``'s heating h0 = 20 W/m^2K,
  4.7 s at its cooling h0 = 41 and 2.8 s at Table II's h0 = 70 (the h2 T^2 term shortens them
  by up to a fifth at 100 degC), against t_P = 1 ms; the ripple is P' t_P / (M_w C_p),
  0.03 degC at 8 V. Steps need not end at PWM edges, so they can be long.
- ``sampled``: the drive is read at each stage time of the integrator, as the authors' Simulink
  model does (``authors-ode4``; its control block ``SMA1_Control_Signal.m``): the stage times
  are those of Simulink's fixed-step ode4, in floating point: T0 = n h, T0 + 0.5 h (twice)
  and (n + 1) h (its ``rt_ertODEUpdateContinuousStates``: ``temp = 0.5 * h``,
  ``rtsiSetT(si, t + temp)``, then ``tnew``, the solver stop time (clockTick + 1) h; the
  convention of Simulink's normal-mode time arithmetic is not in the authors' files). At
  each the period's reference time moves to the stage time if ``time - tRef >= periodDC``,
  and a wire is at ``level`` if DC% > 0 and ``time - tRef <= DC%/100 periodDC``. With
  h = t_P = 1 ms the round-off of ``time - tRef`` decides, step by step, whether the periods
  start at the steps or half-way through them (:func:`sampled_phases`), and so how much of
  each period the four stages see as on: for 0 < DC% < 50 the RK4 weights give a wire 1/6
  to 2/3 of V_H^2, about 0.39 on average over 20 s (0.77 for 50 <= DC% < 100).

Whichever model applies the drive, the interlock (two opposing wires driven at once, Sec. 2.6)
is checked on the resolved wave: with ``averaged`` a step counts as a violation when two
opposing wires both have a duty above 0, since both are on at every period start.
"""

from __future__ import annotations

import math
from enum import IntEnum

from ..jit import njit
from .clock import TICKS_PER_S


class PwmModel(IntEnum):
    EXACT = 0
    AVERAGED = 1
    SAMPLED = 2  #: only through the method that samples it (``authors-ode4``)

    @property
    def label(self) -> str:
        return self.name.lower()


#: the models a user chooses by name (``sampled`` comes with ``method="authors-ode4"``)
PWM_MODELS = {m.label: m for m in (PwmModel.EXACT, PwmModel.AVERAGED)}


def get(name: str) -> PwmModel:
    """The PWM model named ``name`` (``exact`` or ``averaged``)."""
    try:
        return PWM_MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"pwm = {name!r} is not one of {', '.join(PWM_MODELS)}") from None


@njit(cache=True, forceinline=True)
def averaged_drive(level, low, duty_percent):
    """The drive whose square is the PWM wave's mean square over a period (Eq. 12b, Eq. 11)."""
    if duty_percent >= 100.0:
        return level
    if duty_percent <= 0.0:
        return low
    d = duty_percent / 100.0
    return math.sqrt(d * level * level + (1.0 - d) * low * low)


@njit(cache=True, forceinline=True)
def sampled_drive(level, low, duty_percent, on, phase):
    """The PWM wave read at ``phase`` into its period as the authors' model reads it (``<=`` t_DC).

    ``on`` and ``phase`` in seconds, as their model compares them."""
    if duty_percent > 0.0 and phase <= on:
        return level
    return low


@njit(cache=True, forceinline=True)
def _solver_time(ticks, dt_ticks):
    """A fixed-step solver's time at ``ticks``: n h for the step's n-th end, as Simulink counts it."""
    if ticks % dt_ticks == 0:
        return (ticks // dt_ticks) * (dt_ticks / TICKS_PER_S)
    return ticks / TICKS_PER_S


@njit(cache=True, forceinline=True)
def _advanced(t, t_ref, period):
    """The authors' ``if (time - tRef) >= periodDC, tRef = time``."""
    return t if t - t_ref >= period else t_ref


@njit(cache=True, forceinline=True)
def sampled_phases(a, b, dt_ticks, pwm_ticks, t_ref):
    """(phase at the first stage, at the two middle ones, at the last [s], reference time after).

    The stages of a step [a, b] (ticks) of Simulink's ode4 sit at T0, T0 + 0.5 h and T1
    (:func:`_solver_time`; h = b - a in seconds, the fixed step unless an event cut the step);
    ``t_ref`` is the PWM period's reference time, carried from step to step (0 at the start,
    ``tRef = 0`` in ``Initialization.m``).
    """
    period = pwm_ticks / TICKS_PER_S
    t0 = _solver_time(int(a), dt_ticks)
    t1 = _solver_time(int(b), dt_ticks)
    t_ref = _advanced(t0, t_ref, period)
    p0 = t0 - t_ref
    tm = t0 + 0.5 * ((b - a) / TICKS_PER_S)
    t_ref = _advanced(tm, t_ref, period)
    pm = tm - t_ref
    t_ref = _advanced(t1, t_ref, period)
    return p0, pm, t1 - t_ref, t_ref
