"""Phase selection (end of Sec. 2.6) and the strategies of Sec. 4, for any number of wires.

Phase selection: a wire whose contraction raises q (the paper's upper actuator, direction +1)
is in its heating phase while q_F >= q and in its cooling phase otherwise; a wire whose
contraction lowers q (the lower actuator, direction -1) while q_F <= q (the paper states it for
both signs of the desired rotation, and both statements reduce to this). In its heating phase
an enabled wire gets the PID duty (with the error's sign reversed for direction -1); in its
cooling phase it gets the same duty if the controller is kept on in cooling (Fig. 11 case i)
and 0 V otherwise.

Because a direction +1 wire gets clamp(u) and a direction -1 wire clamp(-u) from one PID
output u, opposing wires are never both driven: the interlock (two opposing wires never heated
at once) holds by construction, and the engine checks it at every step anyway.

Strategies:
- ``open-loop``: a piecewise-constant program per wire, no controller.
- ``independent`` (Sec. 4.1): one actuator at a time, the agonist of the desired motion; the
  other is a passive bias spring. Before a new agonist is used, the strategy waits for the end
  of the previous agonist's cooling phase (its wire back to martensite): every wire pulling
  against the new agonist, whether the strategy chose it or a segment enabled it by name, must
  be back to martensite (xi >= ``RELEASE_XI``).
- ``cooperative`` (Sec. 4.2): every actuator enabled; the antagonist heats as soon as the
  mechanism passes the target, i.e. just before the agonist starts cooling.

Which wires are enabled is a bit mask (bit i: wire i); :data:`AUTO` lets the strategy choose.
"""

from enum import IntEnum
from typing import NamedTuple

from ..jit import njit
from .pid import clamp_duty


class Strategy(IntEnum):
    OPEN_LOOP = 0
    INDEPENDENT = 1
    COOPERATIVE = 2

    @property
    def label(self) -> str:
        return self.name.lower().replace("_", "-")


STRATEGIES = {s.label: s for s in Strategy}

#: enable mask meaning "the strategy chooses"
AUTO = -1
#: no wire (an agonist index meaning none)
NO_WIRE = -1
#: martensite fraction above which the independent strategy deems a cooling phase over
RELEASE_XI = 0.999


class Command(NamedTuple):
    """What the controller commands one wire, held until the next control tick."""

    enabled: bool
    heating: bool  #: in its controller's heating phase (selects h, Eq. 11; and C_DF)
    duty: float  #: DC% (Eq. 12)
    level: float  #: drive while on: V_H, or the program's voltage/current


def enable_mask(enable: str, wire_names: tuple[str, ...]) -> int:
    """A profile segment's enable word as a bit mask (:data:`AUTO` for ``auto``)."""
    if enable == "auto":
        return AUTO
    if enable == "none":
        return 0
    if enable in ("both", "all"):
        return (1 << len(wire_names)) - 1
    if enable in wire_names:
        return 1 << wire_names.index(enable)
    raise ValueError(f"enable {enable!r} is not one of auto, none, all, both, {', '.join(wire_names)}")


@njit(cache=True)
def is_enabled(mask, i):
    return (mask >> i) & 1 == 1


@njit(cache=True, forceinline=True)
def heating_phase(direction, q_target, q):
    """Sec. 2.6: the wire's heating phase (upper: theta_F >= theta; lower: theta_F <= theta)."""
    if direction > 0.0:
        return q_target >= q
    return q_target <= q


@njit(cache=True, forceinline=True)
def wire_command(u, enabled, direction, q_target, q, keep_on_in_cooling, level):
    """One wire's :class:`Command` from the PID output u [%]."""
    if not enabled:
        return Command(False, False, 0.0, level)
    heating = heating_phase(direction, q_target, q)
    duty = clamp_duty(direction * u) if heating or keep_on_in_cooling else 0.0
    return Command(True, heating, duty, level)


@njit(cache=True)
def agonist_of(wires, q_target, q, previous):
    """Index of the first wire whose contraction moves q toward q_target (``previous`` at the target)."""
    if q_target == q:
        return previous
    want = 1.0 if q_target > q else -1.0
    for i in range(len(wires)):
        if wires[i].direction == want:
            return i
    return NO_WIRE


@njit(cache=True, forceinline=True)
def opposing_wires_driven(wires, drives, low):
    """The interlock: two wires pulling opposite ways both driven above V_L."""
    up = False
    down = False
    for i in range(len(wires)):
        if drives[i] > low:
            if wires[i].direction > 0.0:
                up = True
            else:
                down = True
    return up and down
