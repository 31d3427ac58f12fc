"""Hysteresis operator for the cosine phase kinetics, Eqs. (9)-(10), with return-point memory.

The major curves are those of Eqs. (9b)/(10b) with xi_M0 = 1 and xi_A0 = 0:

    g_A(tau_A), tau_A = T - sigma/c_A   (heating, from full martensite),
    g_M(tau_M), tau_M = T - sigma/c_M   (cooling, from full austenite),

computed by :func:`smafinger.model.kinetics.g_heating` / ``g_cooling``. Every branch is an
affine image of one major curve, written about its anchor (g0, x0):

    heating:  xi = x0 + b (g_A(tau_A) - g0),    cooling:  xi = x0 + b (g_M(tau_M) - g0),

with b >= 0 (so a = x0 - b g0 in ``xi = a + b g``). Three rules share this record
(``docs/hysteresis.md``):

``"memory"`` (default)
    return-point memory (Madelung's rules): a reversal pushes the current point on a stack
    and starts a branch through it aimed at the previous reversal point of the other kind;
    passing that target wipes the inner loop out and resumes the branch that led to it.
    Stack operations: :mod:`smafinger.model.hysteresis_memory`.
``"authors2020"``
    the authors' 2020 model: branch from the sign of dT/dt, start value re-solved so that
    the new branch passes through the current xi (``minor_loop_reversal_C = 0``).
``"deadband"``
    the same with a reversal threshold in degC (today's paper2010 rule, 0.5 degC).

The legacy rules call the functions of :mod:`smafinger.model.kinetics` (``next_branch``,
``branch_start``) and evaluate with the same floating-point operations as
``martensite_fraction``, so they reproduce today's results to the bit.

Engine protocol, per wire: ``initial_record`` once; at every sub-step start
``drive_direction`` (from dT/dt and dsigma/dt) then ``update_memory``; at every RHS stage
``xi_on_branch``. The record is a NamedTuple of numbers (passed by value in numba); the
stack is a float64 array ``(capacity, STACK_COLUMNS)`` owned by the engine
(:func:`new_stack`).
"""

import math
from typing import NamedTuple

import numpy as np

from ..jit import njit
from .hysteresis_memory import STACK_COLUMNS, branch_target, memory_update
from .kinetics import (COOLING, HEATING, HOLD, branch_start, g_cooling, g_cooling_upper_bound, g_heating,
                       g_heating_lower_bound, next_branch)

MEMORY = 0
AUTHORS2020 = 1
DEADBAND = 2
#: the authors' rule as their Simulink model runs it, one call per model evaluation
#: (:mod:`smafinger.model.hysteresis_authors`; method ``authors-ode4`` only, not a user's choice)
AUTHORS_CALLS = 3
RULES = {"memory": MEMORY, "authors2020": AUTHORS2020, "deadband": DEADBAND}
DEFAULT_RULE = "memory"
UNCLIPPED = False
DEFAULT_CAPACITY = 64
MIN_CAPACITY = 4


class KineticsMaterial(NamedTuple):
    """Transformation temperatures at zero stress (degC) and stress coefficients (Pa/degC)."""

    A_S0_C: float
    A_F0_C: float
    M_S0_C: float
    M_F0_C: float
    c_A_Pa_per_C: float
    c_M_Pa_per_C: float


class BranchRecord(NamedTuple):
    """The current kinetics branch of one wire (numbers only: numba passes it by value).

    ``direction``: +1 heating branch (Eq. 9, driven by tau_A), -1 cooling branch (Eq. 10,
    driven by tau_M), 0 hold (virgin state, or the legacy rules' hold): xi = ``x0``.
    On a branch xi = x0 + slope (g - g0). Memory rule: ``lim_tau`` is the extreme of the
    branch's own tau at the last update and ``lim_g`` g there; xi holds at its value there
    while tau is back from it (a hold, or a turn within a sub-step). The branch ends at its
    target (``target_tau`` in the branch's own tau, +-inf when the branch runs to the end of the
    major curve); past it ``xi_on_branch`` continues on the parent branch (the branch that
    led to the target), so the evaluation stays continuous within a sub-step.
    ``turn_C`` and ``reversal_C`` belong to the dead-band rule; ``clamps`` counts committed
    clamps to the major loop, ``merges`` stack-overflow merges (memory rule). Rule
    ``AUTHORS_CALLS`` keeps the authors' globals Es, Ef, Esave in ``parent_x0``,
    ``parent_slope`` and ``target_xi`` (:mod:`smafinger.model.hysteresis_authors`).
    """

    rule: int
    direction: int
    x0: float
    g0: float
    slope: float
    lim_tau: float
    lim_g: float
    target_tau: float
    target_xi: float
    parent_x0: float
    parent_g0: float
    parent_slope: float
    turn_C: float
    reversal_C: float
    clamps: int
    merges: int


def _float(v) -> float:
    """``v`` as a float; an int beyond any float as inf, which the check then names (it was an
    OverflowError; found by an API fuzz)."""
    try:
        return float(v)
    except OverflowError:
        return math.inf


def kinetics_material(A_S0_C, A_F0_C, M_S0_C, M_F0_C, c_A_Pa_per_C, c_M_Pa_per_C):
    """A validated :class:`KineticsMaterial` (floats).

    Raises
    ------
    ValueError
        Naming the field and value, unless A_F0 > A_S0, M_S0 > M_F0, A_S0 > M_F0,
        A_F0 > M_S0 (the major loop is not empty at zero stress) and c_A, c_M > 0.
    """
    m = KineticsMaterial(*(_float(v) for v in (A_S0_C, A_F0_C, M_S0_C, M_F0_C, c_A_Pa_per_C,
                                              c_M_Pa_per_C)))
    for name in m._fields:
        if not math.isfinite(getattr(m, name)):
            raise ValueError(f"{name} = {getattr(m, name)} is not a finite number")
    checks = (("A_F0_C", m.A_F0_C > m.A_S0_C, f"must exceed A_S0_C = {m.A_S0_C}"),
              ("M_S0_C", m.M_S0_C > m.M_F0_C, f"must exceed M_F0_C = {m.M_F0_C}"),
              ("A_S0_C", m.A_S0_C > m.M_F0_C, f"must exceed M_F0_C = {m.M_F0_C}"),
              ("A_F0_C", m.A_F0_C > m.M_S0_C, f"must exceed M_S0_C = {m.M_S0_C}"),
              ("c_A_Pa_per_C", m.c_A_Pa_per_C > 0.0, "must be positive"),
              ("c_M_Pa_per_C", m.c_M_Pa_per_C > 0.0, "must be positive"))
    for name, ok, why in checks:
        if not ok:
            raise ValueError(f"{name} = {getattr(m, name)} {why}")
    return m


def material_from_parameters(p):
    """The :class:`KineticsMaterial` of a ParameterSet (fields A_S0_C ... c_M_Pa_per_C)."""
    return kinetics_material(p.A_S0_C, p.A_F0_C, p.M_S0_C, p.M_F0_C, p.c_A_Pa_per_C,
                             p.c_M_Pa_per_C)


def max_loop_stress_Pa(m):
    """Largest stress at which the major loop is not empty: g_M(tau_M) <= g_A(tau_A).

    tau_M = tau_A + sigma (1/c_A - 1/c_M): the cooling curve shifts against the heating curve
    when c_A != c_M. For c_A <= c_M the loop never closes (inf); for c_A > c_M it closes at
    sigma = min(A_S0 - M_F0, A_F0 - M_S0) / (1/c_M - 1/c_A).
    """
    shift = 1.0 / m.c_M_Pa_per_C - 1.0 / m.c_A_Pa_per_C
    if shift <= 0.0:
        return math.inf
    return min(m.A_S0_C - m.M_F0_C, m.A_F0_C - m.M_S0_C) / shift


def rule_code(name):
    """Integer code of a rule name (``"memory"``, ``"authors2020"``, ``"deadband"``)."""
    if name not in RULES:
        raise ValueError(f"kinetics rule = {name!r} is not one of {sorted(RULES)}")
    return RULES[name]


def new_stack(capacity=DEFAULT_CAPACITY):
    """The reversal-point stack of one wire: zeros of shape (capacity, STACK_COLUMNS)."""
    if int(capacity) != capacity or capacity < MIN_CAPACITY:
        raise ValueError(f"capacity = {capacity} must be an integer >= {MIN_CAPACITY}")
    return np.zeros((int(capacity), STACK_COLUMNS))


@njit(cache=True)
def major_loop(T, sigma, m):
    """Bounds of the major loop at (T, sigma): (g_M(tau_M), g_A(tau_A)) (Eqs. 9b, 10b)."""
    gA = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
    gM = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
    return gM, gA


@njit(cache=True)
def initial_record(rule, xi_init, T_init, reversal_C):
    """Virgin state: hold at ``xi_init``; returns (record, depth 0).

    The wire holds until its first motion, so the initial stress is not needed: the point
    that matters is where it starts to move.

    Memory rule: at the first motion the wire is taken to have arrived where it is along the
    simplest history that gives xi_init there: on a major curve (xi_init = 1 below A_S: the
    major heating curve; xi_init = 0 above M_S: the major cooling curve) that curve; inside
    the loop, from full martensite along the major heating curve to a reversal point R, then
    cooling along the first-order curve from R (a paper-style scaled curve) to here. A point
    outside the major loop is first clamped into it (counted in ``clamps``).
    Legacy rules: today's initial HOLD with the turning temperature at T_init.
    ``reversal_C`` is the dead-band threshold (used by ``"deadband"`` only).
    """
    rec = BranchRecord(rule, 0, xi_init, 0.0, 0.0, 0.0, 0.0, math.inf, xi_init, xi_init, 0.0,
                       0.0, T_init, reversal_C, 0, 0)
    return rec, 0


@njit(cache=True, forceinline=True)
def xi_on_branch(rec, T, sigma, m):
    """xi and its partial derivatives (dxi/dT, dxi/dsigma) on the record's branch.

    Pure and allocation-free (called at every RHS stage). Memory rule: xi holds while the
    branch's tau is back from its extreme (``lim_tau``), the parent branch is used once tau
    has reached the target, and the result is kept inside the major loop
    g_M(tau_M) <= xi <= g_A(tau_A) (a rounding-level guard; see ``update_memory``).
    Legacy rules: ``kinetics.martensite_fraction``'s operations, clipped to [0, 1] (not
    ``AUTHORS_CALLS``: the authors' functions do not clip).
    """
    d = rec.direction
    if d == 0:
        return rec.x0, 0.0, 0.0
    if rec.rule != MEMORY:
        if d > 0:
            g, gT, gs = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
        else:
            g, gT, gs = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
        xi = rec.x0 + rec.slope * (g - rec.g0)
        if rec.rule == AUTHORS_CALLS:  # their E is not clipped
            return xi, rec.slope * gT, rec.slope * gs
        if xi > 1.0:
            return 1.0, 0.0, 0.0
        if xi < 0.0:
            return 0.0, 0.0, 0.0
        return xi, rec.slope * gT, rec.slope * gs
    if d > 0:
        own = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
        tau = T - sigma / m.c_A_Pa_per_C
        back = tau < rec.lim_tau
        past = tau >= rec.target_tau
    else:
        own = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
        tau = T - sigma / m.c_M_Pa_per_C
        back = tau > rec.lim_tau
        past = tau <= rec.target_tau
    g, gT, gs = own
    if back:
        x0, g0, b = rec.x0, rec.g0, rec.slope
        g, gT, gs = rec.lim_g, 0.0, 0.0
    elif past:
        x0, g0, b = rec.parent_x0, rec.parent_g0, rec.parent_slope
    else:
        x0, g0, b = rec.x0, rec.g0, rec.slope
    return _into_major_loop(d, own, x0 + b * (g - g0), b * gT, b * gs, T, sigma, m)


@njit(cache=True, forceinline=True)
def _into_major_loop(d, own, xi, xT, xs, T, sigma, m):
    """(xi, xi_T, xi_sigma) kept in the major loop: raised to g_M(tau_M), then lowered to g_A(tau_A).

    ``own`` is the branch's own major curve at (T, sigma) (g_A heating, g_M cooling); the other
    curve is evaluated only where a cosine-free bound does not already show that it cannot
    bind (``kinetics.g_cooling_upper_bound``, ``g_heating_lower_bound``): the same result.
    """
    if d > 0:
        if xi < g_cooling_upper_bound(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C):
            gM = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
            if xi < gM[0]:
                xi, xT, xs = gM
        if xi > own[0]:
            xi, xT, xs = own
        return xi, xT, xs
    if xi < own[0]:
        xi, xT, xs = own
    if xi > g_heating_lower_bound(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C):
        gA = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
        if xi > gA[0]:
            xi, xT, xs = gA
    return xi, xT, xs


@njit(cache=True, forceinline=True)
def drive_direction(rec, dT_dt, dsigma_dt, m):
    """Direction for ``update_memory`` from the derivatives at a sub-step start.

    Memory rule: +1 while tau_A rises, -1 while tau_M falls, 0 when neither; when both
    (possible only with c_A != c_M) the current direction is kept (a virgin wire takes the
    sign of the mean tau rate, +1 on a tie). With c_A = c_M this is the sign of dtau/dt.
    Legacy rules: the sign of dT/dt (the authors' model).
    """
    if rec.rule != MEMORY:
        if dT_dt > 0.0:
            return 1
        if dT_dt < 0.0:
            return -1
        return 0
    dA = dT_dt - dsigma_dt / m.c_A_Pa_per_C
    dM = dT_dt - dsigma_dt / m.c_M_Pa_per_C
    heat = dA > 0.0
    cool = dM < 0.0
    if heat and cool:
        if rec.direction != 0:
            return rec.direction
        return 1 if dA + dM >= 0.0 else -1
    if heat:
        return 1
    if cool:
        return -1
    return 0


@njit(cache=True)
def _legacy_update(rec, T, sigma, direction, m):
    """Today's rules (``kinetics.next_branch`` / ``branch_start``) on the record."""
    old = HEATING if rec.direction > 0 else (COOLING if rec.direction < 0 else HOLD)
    nb, turn = next_branch(old, float(direction), T, rec.turn_C, rec.reversal_C)
    d, x0, slope = rec.direction, rec.x0, rec.slope
    if nb != old:
        xi_now = xi_on_branch(rec, T, sigma, m)[0]
        if nb == HOLD:
            d, x0, slope = 0, xi_now, 0.0
        else:
            st = branch_start(nb, xi_now, T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C,
                              m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
            if nb == HEATING:
                d, x0, slope = 1, 0.0, st  # xi = start g_A  (Eq. 9b)
            else:
                d, x0, slope = -1, st, 1.0 - st  # xi = start + (1 - start) g_M  (Eq. 10b)
    return BranchRecord(rec.rule, d, x0, 0.0, slope, 0.0, 0.0, math.inf, x0, x0, 0.0, slope,
                        turn, rec.reversal_C, rec.clamps, rec.merges)


@njit(cache=True, forceinline=True)
def update_memory(rec, stack, depth, T, sigma, direction, m):
    """Commit the sub-step's events at (T, sigma) and choose the branch for the next one.

    Memory rule (:func:`smafinger.model.hysteresis_memory.memory_update`): wipe out every
    loop whose target tau has been reached, clamp to the major loop if needed (counted), and
    on a reversal (``direction`` = -current) push the current point and start the new branch
    through it. ``direction`` 0 keeps the branch. Legacy rules: today's branch selection.
    Returns (record, depth).
    """
    if rec.rule == AUTHORS_CALLS:  # each call commits its own globals (hysteresis_authors)
        return rec, depth
    if rec.rule != MEMORY:
        return _legacy_update(rec, T, sigma, direction, m), depth
    out = memory_update(rec.direction, rec.x0, rec.g0, rec.slope, rec.lim_tau, rec.lim_g,
                        rec.clamps, rec.merges, stack, depth, T, sigma, direction, m)
    d, x0, g0, slope, lim_tau, lim_g, clamps, merges, depth = out
    if d == 0:
        return rec, depth
    t_tau, t_xi, px0, pg0, pslope = branch_target(stack, depth, d, x0, g0, slope)
    return BranchRecord(MEMORY, d, x0, g0, slope, lim_tau, lim_g, t_tau, t_xi, px0, pg0,
                        pslope, rec.turn_C, rec.reversal_C, clamps, merges), depth
