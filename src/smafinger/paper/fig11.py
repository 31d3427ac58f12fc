"""Fig. 11 (Sec. 4.1): the controller kept on (i) or switched off (ii) in the upper wire's
cooling phase, extension -40 -> -30 deg with the upper actuator, parameter set ``paper2010``.

The paper: (ii) "resulted in a relatively faster cooling but a tendency to overshoot the
desired joint position". One criterion, written once (:func:`_checks`), is applied to both
readings of "the cooling phase":

- *v1*: the return from -30 deg to the rest angle after a 10 s hold, at the paper's 23 degC;
- *v2*: the upper wire's own cooling phase by Sec. 2.6, the joint past -30 deg during the
  extension, with wire and surroundings at the 60 degC of the authors' model.

Overshoot has one definition (:func:`smafinger.metrics.overshoot_deg`): how far the joint goes
past a target in the direction of the move to it. For v2 the move is the extension (past
-30 deg upwards); for v1 it is the return (past the rest angle downwards). How far the joint
then falls back past the target the other way is reported separately, as the fall-back.
"""

from __future__ import annotations

from functools import partial

from ..parameters import get as get_params
from . import figures
from .claim import Check, Claim, known
from .derived import CoolingPhase, MoveAndReturn
from .fmt import num, secs
from .overrides import Overrides
from .scenario import MOVE_S, PAPER_FRICTION, Figure, Scenario

PARAMS = "paper2010"
P2010 = get_params(PARAMS)
#: the rest position, where the move starts and the v1 reading returns [deg]
REST_DEG = P2010.theta0_deg
#: the extension's target [deg]
TARGET_DEG = -30.0
#: Sec. 4.1: "a controller update rate of 0.01 s"
UPDATE_S = 0.01
#: v2: wire and surroundings at the temperature of the authors' 2020 model [degC]
WARM_C = get_params("authors2020").T_amb_C
#: "a relatively faster cooling": (ii)'s cooling phase is shorter than this times (i)'s ...
COOLING_RATIO = 0.8
#: ... and (v2, where the phase has a temperature fall) its wire cools more than this many times as fast
RATE_FACTOR = 1.5
#: "a tendency to overshoot": (ii) goes past the target more than this times (i) ...
OVERSHOOT_FACTOR = 2.0
#: ... and by more than this [deg]
OVERSHOOT_MIN_DEG = 0.02


def overshoot_mark(run) -> tuple[float, float, float]:
    """(target, direction, overshoot) of the move a Fig. 11 run's claim reads, for the figure."""
    d = run.derived
    if "cooling_phase" in d:
        return TARGET_DEG, 1.0, d["cooling_phase"]["overshoot_deg"]
    return REST_DEG, -1.0, d["return"]["overshoot_deg"]


def _scenario(version: int, on: bool) -> Scenario:
    lab = "on" if on else "off"
    ov = PAPER_FRICTION.then(Overrides.of(controller_in_cooling=on, controller_update_s=UPDATE_S))
    common = dict(figure="Fig. 11", params=PARAMS, strategy="independent", wire="upper",
                  label="(i) controller on in cooling" if on else "(ii) controller off in cooling")
    kept = "kept on" if on else "switched off"
    if version == 1:
        return Scenario(
            name=f"fig11-controller-{lab}-v1", group="fig11-return",
            description=(f"Fig. 11, Sec. 4.1: extension {REST_DEG:g} -> {TARGET_DEG:g} deg with the upper actuator "
                         f"only (held {MOVE_S:g} s), then back to {REST_DEG:g} deg through its cooling phase; "
                         f"controller {kept} in the cooling phase, update {UPDATE_S:g} s"),
            profile=f"0:{TARGET_DEG:g}:upper,{MOVE_S:g}:{REST_DEG:g}:upper", t_end_s=2.5 * MOVE_S, overrides=ov,
            derive=MoveAndReturn(), **common)
    return Scenario(
        name=f"fig11-controller-{lab}-v2", group="fig11",
        description=(f"Fig. 11, Sec. 4.1: extension {REST_DEG:g} -> {TARGET_DEG:g} deg with the upper actuator only; "
                     f"controller {kept} in the upper wire's cooling phase (joint past the target), update "
                     f"{UPDATE_S:g} s; wire and surroundings at {WARM_C:g} degC as in the authors' model"),
        profile=f"0:{TARGET_DEG:g}:upper", t_end_s=2 * MOVE_S,
        overrides=ov.then(Overrides.of(T_init_C=WARM_C, T_amb_C=WARM_C)),
        derive=CoolingPhase(target_deg=TARGET_DEG, wire="upper"), **common)


V1 = (_scenario(1, True), _scenario(1, False))
V2 = (_scenario(2, True), _scenario(2, False))


def _checks(rate: bool) -> tuple[Check, ...]:
    """Fig. 11's criterion on ``{on, off}`` values with ``cooling_s``, ``overshoot_deg`` and
    (``rate``) ``cooling_rate_C_s``."""
    def both(v, key):
        return known(v["on"][key], v["off"][key])

    faster = Check(f"(ii)'s cooling phase shorter than {COOLING_RATIO:g} x (i)'s",
                   lambda v: both(v, "cooling_s") and v["off"]["cooling_s"] < COOLING_RATIO * v["on"]["cooling_s"])
    cools = Check(f"(ii)'s wire cools more than {RATE_FACTOR:g} x as fast",
                  lambda v: both(v, "cooling_rate_C_s")
                  and v["off"]["cooling_rate_C_s"] > RATE_FACTOR * v["on"]["cooling_rate_C_s"])
    overshoots = Check(f"(ii) goes past the target (in the direction of the move) more than {OVERSHOOT_FACTOR:g} x "
                       f"(i) and by more than {OVERSHOOT_MIN_DEG:g} deg",
                       lambda v: both(v, "overshoot_deg") and v["off"]["overshoot_deg"]
                       > max(OVERSHOOT_FACTOR * v["on"]["overshoot_deg"], OVERSHOOT_MIN_DEG))
    return (faster, cools, overshoots) if rate else (faster, overshoots)


def _by_key(runs: list) -> dict:
    return {r.key: r for r in runs}


def _v2_measure(runs: list) -> dict:
    r = _by_key(runs)
    v1 = r.get(V1[0].name)
    return {"on": r[V2[0].name].derived["cooling_phase"], "off": r[V2[1].name].derived["cooling_phase"],
            "past_v1_deg": None if v1 is None else v1.derived["move"]["overshoot_deg"]}


def _v2_shows(v: dict) -> str:
    on, off = v["on"], v["off"]
    if not known(on["cooling_s"], off["cooling_s"]):
        return f"the joint never passed {TARGET_DEG:g} deg"
    return (f"overshoot past {TARGET_DEG:g} deg: on {num(on['overshoot_deg'], '.3f', ' deg')}, off "
            f"{num(off['overshoot_deg'], '.3f', ' deg')}; cooling phase: on {secs(on['cooling_s'], '.2f')} at "
            f"{num(on['cooling_rate_C_s'], '.1f', ' °C/s')}, off {secs(off['cooling_s'], '.2f')} at "
            f"{num(off['cooling_rate_C_s'], '.1f', ' °C/s')}; then falls back below {TARGET_DEG:g} deg by: on "
            f"{num(on['fall_back_deg'], '.3f', ' deg')}, off {num(off['fall_back_deg'], '.3f', ' deg')}")


def _v2_note(v: dict) -> str:
    text = f"reading v2: wire and surroundings at the authors' {WARM_C:g} °C"
    if v["past_v1_deg"] is not None:
        text += (f"; at the paper's {P2010.T_amb_C:g} °C (v1) the joint passes {TARGET_DEG:g} deg by only "
                 f"{v['past_v1_deg']:.3f} deg, so there is hardly a cooling phase to control")
    on, off = v["on"], v["off"]
    if known(on["overshoot_deg"], off["overshoot_deg"], on["fall_back_deg"], off["fall_back_deg"]):
        text += (f". (ii) passes the target by {off['overshoot_deg'] - on['overshoot_deg']:+.4f} deg more than (i): "
                 f"the first excursion is over before the two controllers differ. After its cooling phase (ii) falls "
                 f"back {off['fall_back_deg']:.3f} deg below the target and (i) {on['fall_back_deg']:.3f} deg: a "
                 "fall back against the direction of the move, which the paper may have called overshoot")
    return text


def _v1_measure(runs: list) -> dict:
    r = _by_key(runs)
    out = {}
    for k, s in (("on", V1[0]), ("off", V1[1])):
        run = r[s.name]
        ret = run.derived["return"]
        out[k] = {"cooling_s": ret["reached_s"], "overshoot_deg": ret["overshoot_deg"],
                  "peak_duty": ret["peak_duty_upper"], "past_deg": run.derived["move"]["overshoot_deg"],
                  "electrical_J": run.summary["electrical_energy_J"]["upper"],
                  "heat_J": run.summary["heat_J"]["upper"]}
    return out


def _v1_shows(v: dict) -> str:
    on, off = v["on"], v["off"]
    return (f"return to {REST_DEG:g} deg: on {secs(on['cooling_s'], '.2f')}, off {secs(off['cooling_s'], '.2f')}; "
            f"overshoot past {REST_DEG:g} deg: on {on['overshoot_deg']:.3f} deg, off {off['overshoot_deg']:.3f} deg; "
            f"upper wire: heat put into it on {on['heat_J']:.1f} J, off {off['heat_J']:.1f} J (electrical energy at "
            f"its terminals {on['electrical_J']:.0f} J, {off['electrical_J']:.0f} J)")


def _v1_note(v: dict) -> str:
    duty = v["on"]["peak_duty"]
    heat = ("applies 0 V during the return, as 'off' does, so the two differ only by the state the hold "
            "leaves them in" if duty == 0.0 else f"heats the upper wire at up to {duty:.1f}% duty during the return")
    return (f"with the controller on, the PID {heat}; during the hold the joint goes at most "
            f"{max(v['on']['past_deg'], 0.0):.3f} deg past {TARGET_DEG:g} deg (hardly any cooling phase there)")


CLAIMS = (
    Claim(key="fig11-v2", figure="Fig. 11",
          statement=("controller off in the cooling phase: relatively faster cooling, but a tendency to overshoot "
                     f"the target (v2: cooling phase = joint past {TARGET_DEG:g} deg; wire at {WARM_C:g} °C)"),
          paper="(ii) cools faster than (i), and overshoots", scenarios=(V2[0].name, V2[1].name),
          also=(V1[0].name,), measure=_v2_measure, shows=_v2_shows, note=_v2_note, checks=_checks(rate=True),
          known_gap=("with overshoot measured in the direction of the move, (i) and (ii) pass the target by the "
                     "same amount; (ii) differs by falling back below it afterwards")),
    Claim(key="fig11-v1", figure="Fig. 11",
          statement=(f"first reading (v1): cooling phase = the return from {TARGET_DEG:g} to {REST_DEG:g} deg at "
                     f"{P2010.T_amb_C:g} °C; controller off: faster, but overshoots"),
          paper="(ii) faster than (i), with overshoot", scenarios=(V1[0].name, V1[1].name),
          measure=_v1_measure, shows=_v1_shows, note=_v1_note, checks=_checks(rate=False),
          known_gap=("with K_P = K_V and the integral reset at the new target the PID output stays negative during "
                     "the return, so 'on' applies 0 V as 'off' does and the two returns nearly coincide (the values "
                     "beside it)")),
)

FIGURES = (
    Figure("fig11-return", f"Fig. 11, first reading (v1): cooling phase = return to {REST_DEG:g} deg, "
           f"{P2010.T_amb_C:g} °C", partial(figures.cooling_phase, panel=(
               f"(a) Extension {REST_DEG:g} -> {TARGET_DEG:g} deg with the upper actuator, then back to "
               f"{REST_DEG:g} deg"), zoom_deg=0.1, marks=overshoot_mark), V1, CLAIMS[1:]),
    Figure("fig11", f"Fig. 11: controlled (i) vs uncontrolled (ii) cooling phase ({PARAMS}, update {UPDATE_S:g} s, "
           f"wire at {WARM_C:g} °C)", partial(
               figures.cooling_phase, zoom_deg=0.5, marks=overshoot_mark,
               panel=f"(a) Extension {REST_DEG:g} -> {TARGET_DEG:g} deg with the upper actuator (cooling phase: "
                     f"joint past {TARGET_DEG:g} deg)"), V2, CLAIMS[:1]),
)

__all__ = ["FIGURES", "CLAIMS", "V1", "V2", "WARM_C", "UPDATE_S"]
