"""Fig. 10(a) (Sec. 3.2): the temperature inside the actuator casing over three open-loop
on/off cycles, with the two-node thermal model (``thermal_model = "two-node"``).

Sec. 3.2: "the actuator was turned on and off three times consecutively in an open-loop mode,
with about 30 s of cool-down period between each cycle. As expected, it resulted in a stepwise
increase from the initial temperature of around 23 degC, with not enough time to provide
complete cooling between two consecutive cycles." The paper gives neither the on-time nor the
casing's thermal properties; the choices below are ours and named.

Casing (per metre of wire, the two-node model's unit; the paper's wire is 0.385 m long):

- heat capacity :data:`CASING_HEAT_CAPACITY_J_MK` = 20 J/(m K), i.e. 7.7 J/K for the actuator:
  about 5.5 g of polymer (ABS, c_p about 1.4 kJ/(kg K)) with the air inside it;
- loss to the open air :data:`CASING_LOSS_W_MK` = 0.08 W/(m K), i.e. 0.031 W/K: about 31 cm^2 of
  casing surface at h = 10 W/(m^2 K), inside the 2-25 W/(m^2 K) range of free convection in
  gases (Incropera & DeWitt, *Fundamentals of Heat and Mass Transfer*, Table 1.1).

Both are estimates of a Miga actuator's casing, not measurements (they are the parameter set's
defaults, given here explicitly so that the scenario does not move with them). Their time
constant C/G = 250 s is what matters: a 30 s cool-down cannot empty the casing, so its
temperature rises stepwise. A single-node run of the same program is the control.
"""

from __future__ import annotations

from ..parameters import get as get_params
from . import figures
from .claim import Check, Claim, increasing, known, spread
from .derived import OnOffCycles
from .fmt import nums
from .overrides import Overrides
from .scenario import MOVE_S, PAPER_FRICTION, V_H, Figure, Scenario

PARAMS = "paper2010"
P2010 = get_params(PARAMS)
#: Sec. 3.2: three cycles with "about 30 s of cool-down period between each cycle"
CYCLES = 3
OFF_S = 30.0
#: on-time of each cycle (the paper gives none): one closed-loop move's time, MOVE_S [s]
ON_S = MOVE_S
#: casing estimates (module docstring)
CASING_HEAT_CAPACITY_J_MK = 20.0
CASING_LOSS_W_MK = 0.08
#: (on, off) times of the cycles [s]
ON_OFF_S = tuple((k * (ON_S + OFF_S), k * (ON_S + OFF_S) + ON_S) for k in range(CYCLES))
CASING = Overrides.of(casing_heat_capacity_J_mK=CASING_HEAT_CAPACITY_J_MK, casing_loss_W_mK=CASING_LOSS_W_MK)


def _program() -> str:
    """Open-loop voltage program: the upper wire at the set's V_H during each on-time, 0 V otherwise."""
    return ",".join(f"{on:g}:{V_H}:0,{off:g}:0:0" for on, off in ON_OFF_S)


def _scenario(model: str) -> Scenario:
    ov = PAPER_FRICTION.then(CASING).then(Overrides.of(thermal_model=model))
    return Scenario(
        name=f"fig10a-{model}-v1", figure="Fig. 10(a)",
        description=(f"Fig. 10(a), Sec. 3.2: open loop, {P2010.V_H_V:g} V on the upper wire for {ON_S:g} s then "
                     f"{OFF_S:g} s off, {CYCLES} times; {model} thermal model, casing "
                     f"{CASING_HEAT_CAPACITY_J_MK:g} J/(m K) and {CASING_LOSS_W_MK:g} W/(m K) per metre of wire"),
        params=PARAMS, strategy="open-loop", voltage=_program(), t_end_s=ON_OFF_S[-1][0] + ON_S + OFF_S,
        overrides=ov, group="fig10a", panel=model, wire="upper",
        label="two-node: wire -> casing air -> open air" if model == "two-node" else "single node (Eq. 11)",
        derive=OnOffCycles(ON_OFF_S, "upper"))


TWO_NODE, SINGLE_NODE = _scenario("two-node"), _scenario("single-node")


def _measure(runs: list) -> dict:
    r = {x.key: x.derived["cycles"] for x in runs}
    two, one = r[TWO_NODE.name], r[SINGLE_NODE.name]
    return {"casing_start_C": [c["casing_start_C"] for c in two], "casing_end_C": [c["casing_end_C"] for c in two],
            "cooling_s": [c["cooling_s"] for c in two], "single_cooling_s": [c["cooling_s"] for c in one],
            "martensite_s": [c["martensite_s"] for c in two], "T_amb_C": P2010.T_amb_C}


def _shows(v: dict) -> str:
    return (f"casing air at the start of each cycle {nums(v['casing_start_C'], '.1f')} °C, at the end of each "
            f"cool-down {nums(v['casing_end_C'], '.1f')} °C; cooling time of each move (90% of the way back) "
            f"{nums(v['cooling_s'])} s (single node: {nums(v['single_cooling_s'])} s); wire back to martensite "
            f"{nums(v['martensite_s'])} s after the switch-off")


def _grows_more(v: dict) -> bool:
    two, one = v["cooling_s"], v["single_cooling_s"]
    return known(*two, *one) and two[-1] - two[0] > spread(one)


CLAIMS = (Claim(
    key="fig10a", figure="Fig. 10(a)", statement=(
        f"{CYCLES} open-loop on/off cycles with {OFF_S:g} s cool-downs: the casing temperature rises stepwise from "
        "about 23 °C, the cooling between cycles is incomplete, and the cooling time of a move grows"),
    paper="stepwise increase from around 23 °C, incomplete cooling", scenarios=(TWO_NODE.name, SINGLE_NODE.name),
    measure=_measure, shows=_shows,
    checks=(Check(f"each cycle starts warmer than the one before (the first at the ambient {P2010.T_amb_C:g} °C, "
                  "the initial condition)", lambda v: increasing(v["casing_start_C"])),
            Check("each cool-down ends warmer than its cycle began (incomplete cooling)",
                  lambda v: all(e > s for s, e in zip(v["casing_start_C"], v["casing_end_C"]))),
            Check("the cooling time of the move grows from cycle to cycle",
                  lambda v: increasing(v["cooling_s"])),
            Check("it grows by more than the single-node runs' cycles differ", _grows_more)),
    note=(f"on-time {ON_S:g} s at {P2010.V_H_V:g} V (the paper gives none); casing {CASING_HEAT_CAPACITY_J_MK:g} J/(m K), "
          f"{CASING_LOSS_W_MK:g} W/(m K) per metre of wire: estimates, see smafinger.paper.fig10")),)

FIGURES = (Figure("fig10a", f"Fig. 10(a): {CYCLES} open-loop on/off cycles ({ON_S:g} s at {P2010.V_H_V:g} V, "
                  f"{OFF_S:g} s off), two-node thermal model ({PARAMS})", figures.onoff_cycles,
                  (TWO_NODE, SINGLE_NODE), CLAIMS),)

__all__ = ["FIGURES", "CLAIMS", "TWO_NODE", "SINGLE_NODE", "ON_OFF_S", "CASING_HEAT_CAPACITY_J_MK", "CASING_LOSS_W_MK"]
