"""An architecture aimed at speed: temperature-limited rapid heating and antagonist pre-heating.

After Teh and Featherstone, "An architecture for fast and accurate control of shape memory
alloy actuators", Int. J. Robotics Research 27(5):595-611, 2008: a core controller decides how
hard each wire should heat, and mechanisms around it make the heating fast but safe.

- Core: any law of :mod:`.chain` (the PID of Eq. 12a by default), distributed by the paper's
  phase selection (Sec. 2.6).
- Rapid heating: a wire the core heats is driven at ``boost_V`` (a supply above V_H) while its
  measured temperature is below ``boost_until_C``, at V_H above it. Teh and Featherstone's
  rapid-heating mechanism lets the heating current exceed the wire's safe continuous rating
  for as long as the wire is not yet hot; the pulse ends on temperature, not on time.
- Temperature limit: a wire at or above ``T_max_C`` gets no duty (the overheating guard of the
  same architecture, which there reads the temperature from the wire's resistance).
- Pre-heating the antagonist: an enabled wire the core leaves idle is heated at
  ``preheat_duty`` towards ``preheat_C`` (below its A_s: it gets warm, it does not contract),
  so that it starts pulling sooner when its turn comes; only while no opposing wire is driven,
  so the interlock (two opposing wires never heated at once, Sec. 2.6) holds. Teh and
  Featherstone pre-heat the antagonist while the agonist works, which that interlock forbids, so
  here it does little: under the co-operative strategy with the controller on in cooling one of
  the two wires always has a duty, and the run is bit-identical with and without it (the full
  cycle, rk4 at 1 ms, ``preheat_C`` 60, 80 %); under the independent strategy only the agonist is
  enabled, so it is the idle agonist that is kept warm between moves: the same motion within
  2e-8 deg, 113.1 J in the upper wire against 90.2 J.

Teh and Featherstone also keep a minimum tension in both wires (anti-slack). The finger's
spring-slack tendons are pre-tensioned by their bias springs, so neither tendon goes slack in
the moves of the paper: that mechanism is left out (docs/controllers.md).

Sensors: the coordinate and its rate, and a temperature on each wire (Teh and Featherstone
estimate it from the resistance; here it is measured directly).
"""

from typing import NamedTuple

from ..engine.tuples import set_item
from ..jit import njit
from .strategies import Command, is_enabled


class RapidHeating(NamedTuple):
    """The mechanisms around the core controller (its gains are the chain's, :mod:`.chain`)."""

    boost_V: float  #: drive level of the rapid-heating pulse [V] (or A with a current drive)
    boost_until_C: float  #: the pulse lasts while the wire is below this temperature
    T_max_C: float  #: no duty at or above this wire temperature
    preheat_C: float  #: standby temperature of an idle wire (-inf: no pre-heating)
    preheat_duty: float  #: DC% of the pre-heating [%]


@njit(cache=True, forceinline=True)
def _opposing_idle(wires, cmds, i):
    """No wire pulling against wire i has a duty."""
    for k in range(len(wires)):
        if wires[k].direction != wires[i].direction and cmds[k].duty > 0.0:
            return False
    return True


@njit(cache=True, forceinline=True)
def shape_commands(ctrl, model, cmds, m):
    """Rapid heating, the temperature limit and pre-heating, applied to the core's commands.

    A wire is pre-heated only if no opposing wire has a duty in the commands as shaped so far
    (so two idle opposing wires are never pre-heated together).
    """
    w = model.wires
    for i in range(len(w)):
        c = cmds[i]
        T = m.T_C[i]
        if c.duty > 0.0:
            level = ctrl.boost_V if T < ctrl.boost_until_C else c.level
            duty = 0.0 if T >= ctrl.T_max_C else c.duty
            cmds = set_item(cmds, i, Command(c.enabled, c.heating, duty, level))
        elif is_enabled(m.enabled, i) and T < ctrl.preheat_C and _opposing_idle(w, cmds, i):
            cmds = set_item(cmds, i, Command(c.enabled, c.heating, ctrl.preheat_duty, c.level))
    return cmds
