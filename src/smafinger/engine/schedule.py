"""The target schedule (Eq. 12a's theta_F(t)) and the strategies' choice of enabled wires.

A profile is a list of segments (start, target, enable); a start of -1 means "when the
previous target has been reached" (within a tolerance, for a hold time). :func:`advance`
starts the segments that are due; :func:`track_reach` records when each target was reached.
"""

import math
from typing import NamedTuple

from ..control.strategies import AUTO, NO_WIRE, RELEASE_XI, Strategy, agonist_of
from ..jit import njit
from ..model.wire import wire_stress_xi
from .tuples import with_field

#: an enable mask with every wire's bit set
ALL_WIRES = (1 << 62) - 1


class Segments(NamedTuple):
    start: object  #: int64[n] ticks, -1: on reach
    target: object  #: float64[n], SI (rad or m)
    enable: object  #: int64[n] wire masks, AUTO: the strategy chooses


class Schedule(NamedTuple):
    next_seg: int  #: index of the next segment to start
    q_target: float
    enabled: int  #: bit mask of enabled wires
    agonist: int  #: independent strategy: the wire it chose last (NO_WIRE: none yet)
    waiting: bool  #: independent strategy: waiting for the opposing wires to cool
    wait_wire: int  #: the opposing wire waited for
    pending: int  #: the agonist to enable once the wait is over
    band_since: int  #: tick since which q has stayed within the tolerance (-1: outside)
    confirmed: bool  #: the current target has been reached (held for the hold time)


def initial_schedule(q0: float) -> Schedule:
    return Schedule(0, q0, 0, NO_WIRE, False, NO_WIRE, NO_WIRE, -1, False)


@njit(cache=True)
def _xi(model, state, inputs, geom, i):
    """xi of wire i at the state, on its current branch."""
    _, xi = wire_stress_xi(model.wires[i], state.wires[i], inputs.wires[i].branch, geom.routes[i].path_m,
                           model.options.stress_law)
    return xi


@njit(cache=True)
def _unreleased_opponent(model, state, inputs, geom, ag):
    """A wire pulling against wire ``ag`` that is not yet back to martensite (NO_WIRE: none)."""
    for j in range(len(model.wires)):
        if (model.wires[j].direction != model.wires[ag].direction
                and _xi(model, state, inputs, geom, j) < RELEASE_XI):
            return j
    return NO_WIRE


@njit(cache=True)
def _independent(s, target, model, state, inputs, geom, wait_release):
    """Sec. 4.1: enable the agonist once every wire pulling against it is back to martensite.

    The wire waited for is whichever opposing wire is still transformed, whether the strategy
    chose it or a segment enabled it by name.
    """
    ag = agonist_of(model.wires, target, state.q, s.agonist)
    if wait_release and ag != NO_WIRE:
        w = _unreleased_opponent(model, state, inputs, geom, ag)
        if w != NO_WIRE:
            return Schedule(s.next_seg, target, 0, ag, True, w, ag, -1, False)
    return Schedule(s.next_seg, target, 0 if ag == NO_WIRE else 1 << ag, ag, False, s.wait_wire, s.pending,
                    -1, False)


@njit(cache=True)
def advance(s, t, segs, seg_actual, strategy, wait_release, model, state, inputs, geom):
    """Start every segment due at tick t; end an independent strategy's wait if it is over.

    Returns (schedule, started: a segment started or the wait ended).
    """
    started = False
    while s.next_seg < len(segs.start):
        k = s.next_seg
        st = segs.start[k]
        if not ((st >= 0 and st <= t) or (st < 0 and s.confirmed)):
            break
        seg_actual[k] = t
        target = segs.target[k]
        en = segs.enable[k]
        if strategy == Strategy.OPEN_LOOP:
            s = Schedule(k, target, s.enabled, s.agonist, False, s.wait_wire, s.pending, -1, False)
        elif en == AUTO and strategy == Strategy.COOPERATIVE:
            s = Schedule(k, target, ALL_WIRES, s.agonist, False, s.wait_wire, s.pending, -1, False)
        elif en == AUTO and strategy == Strategy.INDEPENDENT:
            s = _independent(s, target, model, state, inputs, geom, wait_release)
        else:
            s = Schedule(k, target, en, s.agonist, False, s.wait_wire, s.pending, -1, False)
        s = with_field(s, "next_seg", k + 1)
        started = True
    if s.waiting and _xi(model, state, inputs, geom, s.wait_wire) >= RELEASE_XI:
        w = _unreleased_opponent(model, state, inputs, geom, s.pending)
        if w == NO_WIRE:
            s = with_field(with_field(s, "waiting", False), "enabled", 1 << s.pending)
            started = True
        else:
            s = with_field(s, "wait_wire", w)
    return s, started


@njit(cache=True, forceinline=True)
def track_reach(s, t, q, tol, hold_ticks, t_prev, q_prev, locate):
    """Track whether the current target has been entered for good (within ``tol`` for ``hold_ticks``).

    ``q`` is the coordinate at tick t, ``q_prev`` at ``t_prev`` (the step's start). The target is
    entered at t, or, with ``locate``, where the line from q_prev to q crosses the band's edge
    (long steps: the event located inside the step, not at its end). Returns (schedule, reached):
    ``reached`` is the tick at which the target of segment ``next_seg - 1`` was entered, on the
    tick this is confirmed; -1 otherwise.
    """
    err = abs(q - s.q_target)
    if err <= tol:
        band = s.band_since
        if band < 0:
            band = t
            err_prev = abs(q_prev - s.q_target)
            if locate and err_prev > tol and t > t_prev:
                band = t_prev + int(math.ceil((t - t_prev) * (err_prev - tol) / (err_prev - err)))
        reached = -1
        confirmed = s.confirmed
        if t - band >= hold_ticks and not confirmed:
            confirmed = True
            if s.next_seg >= 1:
                reached = band
        return with_field(with_field(s, "band_since", band), "confirmed", confirmed), reached
    return with_field(s, "band_since", -1), -1


@njit(cache=True, forceinline=True)
def confirm_tick(s, hold_ticks):
    """The tick at which the current target will count as reached if q stays in the band (-1: none)."""
    if s.band_since >= 0 and not s.confirmed:
        return s.band_since + hold_ticks
    return -1
