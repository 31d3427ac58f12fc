"""Phase selection (end of Sec. 2.6) and the strategies of Sec. 4.

Phase selection: the upper actuator is in its heating phase while theta_F >= theta and in
its cooling phase otherwise; the lower actuator is in its heating phase while
theta_F <= theta (the paper states it for both signs of the desired rotation, and both
statements reduce to this). In its heating phase an enabled actuator gets the PID duty
(the lower one with the error's sign reversed); in its cooling phase it gets the same duty
if the controller is kept on in cooling (Fig. 11 case i) and 0 V otherwise.

Because the upper duty is clamp(u) and the lower one clamp(-u) from one PID output u, at
most one of them is positive: the interlock (both wires never heated at once) holds by
construction, and the engine checks it at every step anyway.

Strategies:
- ``open-loop``: a piecewise-constant voltage program per wire, no controller.
- ``independent`` (Sec. 4.1): one actuator at a time, the agonist of the desired rotation;
  the other is a passive bias spring. Before a new agonist is used, the strategy waits for
  the end of the previous agonist's cooling phase (its wire back to martensite).
- ``cooperative`` (Sec. 4.2): both actuators enabled; the antagonist heats as soon as the
  joint passes the target, i.e. just before the agonist starts cooling.
"""

from numba import njit

OPEN_LOOP = 0
INDEPENDENT = 1
COOPERATIVE = 2
STRATEGIES = {"open-loop": OPEN_LOOP, "independent": INDEPENDENT, "cooperative": COOPERATIVE}

AUTO = 0
UPPER = 1
LOWER = 2
BOTH = 3
NONE = 4
ENABLES = {"auto": AUTO, "upper": UPPER, "lower": LOWER, "both": BOTH, "none": NONE}

#: martensite fraction above which the independent strategy deems a cooling phase over
RELEASE_XI = 0.999


@njit(cache=True)
def upper_heating_phase(theta_F, theta):
    """Sec. 2.6: the upper actuator heats while theta_F >= theta."""
    return theta_F >= theta


@njit(cache=True)
def lower_heating_phase(theta_F, theta):
    """Sec. 2.6: the lower actuator heats while theta_F <= theta."""
    return theta_F <= theta


@njit(cache=True)
def actuator_commands(u, enabled_u, enabled_l, theta_F, theta, keep_on_in_cooling):
    """(duty_u, duty_l, heating_u, heating_l) from the PID output u [%]."""
    duty_u = 0.0
    duty_l = 0.0
    heat_u = False
    heat_l = False
    if enabled_u:
        heat_u = upper_heating_phase(theta_F, theta)
        if heat_u or keep_on_in_cooling:
            duty_u = min(max(u, 0.0), 100.0)
    if enabled_l:
        heat_l = lower_heating_phase(theta_F, theta)
        if heat_l or keep_on_in_cooling:
            duty_l = min(max(-u, 0.0), 100.0)
    return duty_u, duty_l, heat_u, heat_l


@njit(cache=True)
def independent_agonist(theta_F, theta, previous):
    """Agonist of the desired rotation: UPPER for positive, LOWER for negative."""
    if theta_F > theta:
        return UPPER
    if theta_F < theta:
        return LOWER
    return previous
