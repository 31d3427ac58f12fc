"""Sec. 3.1: the open-loop parametric analysis (Figs. 7 and 8 and the other variations).

Each variation heats one wire at the set's V_H for :data:`~.scenario.OPEN_LOOP_ON_S`, then
removes the voltage, with one parameter changed from Table II (``paper2010-table2``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..metrics import REST_SPEED_DEG_S, START_OF_MOTION_DEG
from ..parameters import get as get_params
from . import figures
from .claim import Check, Claim, decreasing, increasing, spread
from .derived import OpenLoop
from .fmt import nums
from .overrides import Overrides
from .scenario import OPEN_LOOP_ON_S, PAPER_FRICTION, V_H, Figure, Scenario

PARAMS = "paper2010-table2"
TABLE2 = get_params(PARAMS)
WIRES = {"upper": "upper wire heated (extension)", "lower": "lower wire heated (flexion)"}
#: a variant has reached its full range if slower than this over the last second of heating
STILL_DEG_S = REST_SPEED_DEG_S
#: C_DF changes the speed, not the range: the ranges agree within this fraction
RANGE_AGREEMENT = 0.10
#: variations of our own where the paper gives no values: +-50% of Table II's h2,
#: V_H +-0.5 V, spring lengths +-0.5 mm
H2_FACTORS = (0.5, 1.0, 1.5)
VH_STEP_V = 0.5
SPRING_STEP_M = 0.5e-3


@dataclass(frozen=True)
class Variation:
    """One parameter varied over ``values`` (SI), each run with either wire heated."""

    key: str
    group: str
    figure: str
    what: str
    fields: tuple[str, ...]
    values: tuple[float, ...]
    unit: str
    label: str
    scale: float = 1.0
    spring_given: bool = False

    def _scenario(self, wire: str, v: float) -> Scenario:
        shown = f"{v * self.scale:g}"
        ov = PAPER_FRICTION.then(Overrides.of(**{f: v for f in self.fields}))
        if self.spring_given:
            ov = ov.then(Overrides.of(spring_init="given"))
        volts = ov.apply(TABLE2).V_H_V  # for the description; the program takes the run's own V_H
        on = f"{V_H}:0" if wire == "upper" else f"0:{V_H}"
        return Scenario(
            name=f"{self.key}-{shown}{'mm' if self.unit == 'mm' else ''}-{wire}-v1",
            figure=self.figure,
            description=(f"{self.figure}, Sec. 3.1: open loop, {volts:g} V on the {wire} wire for "
                         f"{OPEN_LOOP_ON_S:g} s then 0 V; {self.what} = {shown} {self.unit} (Table II "
                         f"otherwise{', spring_init = given' if self.spring_given else ''})"),
            params=PARAMS, strategy="open-loop", voltage=f"0:{on},{OPEN_LOOP_ON_S:g}:0:0",
            t_end_s=2 * OPEN_LOOP_ON_S, overrides=ov, group=self.group, panel=wire,
            label=self.label.format(v=shown), wire=wire, value=v * self.scale, unit=self.unit,
            derive=OpenLoop(t_off_s=OPEN_LOOP_ON_S))

    def scenarios(self) -> tuple[Scenario, ...]:
        return tuple(self._scenario(w, v) for w in WIRES for v in self.values)

    def names(self, wire: str) -> tuple[str, ...]:
        return tuple(s.name for s in self.scenarios() if s.wire == wire)


def by_value(*keys: str):
    """``measure``: the varied values and the open-loop metrics ``keys``, in value order."""
    def measure(runs: list) -> dict:
        runs = sorted((r for r in runs if r.scenario.unit), key=lambda r: r.scenario.value)
        out = {"value": [r.scenario.value for r in runs]}
        out.update({k: [r.derived[k] for r in runs] for k in keys})
        return out
    return measure


def _sweep_claim(v: Variation, wire: str, key: str, figure: str, statement: str, paper: str,
                 keys: tuple[str, ...], shows, checks, **kw) -> Claim:
    return Claim(key=f"{key}-{wire}", figure=figure, statement=f"{statement} ({wire} wire)", paper=paper,
                 scenarios=v.names(wire), min_runs=2, measure=by_value(*keys), shows=shows,
                 checks=checks, **kw)


FIG7 = Variation("fig7-cdf", "fig07-cdf", "Fig. 7", "C_DF", ("C_DF_heating_Nms", "C_DF_cooling_Nms"),
                 (0.02, 0.05, 0.1), "N m s/rad", r"$C_{{DF}}$ = {v} N m s/rad")
FIG8 = Variation("fig8-h0", "fig08-h0", "Fig. 8", "h0", ("h0_heating_W_m2K", "h0_cooling_W_m2K"),
                 (60.0, 65.0, 70.0), "W/(m^2 K)", r"$h_0$ = {v} W/(m$^2$K)")
H2 = Variation("sec31-h2", "sec31-h2", "Sec. 3.1 (h2)", "h2", ("h2_heating_W_m2K3", "h2_cooling_W_m2K3"),
               tuple(f * TABLE2.h2_heating_W_m2K3 for f in H2_FACTORS), "W/(m^2 K^3)",
               r"$h_2$ = {v} W/(m$^2$K$^3$)")
VH = Variation("sec31-vh", "sec31-vh", "Sec. 3.1 (V_H)", "V_H", ("V_H_V",),
               tuple(TABLE2.V_H_V + k * VH_STEP_V for k in (-1, 0, 1)), "V", r"$V_H$ = {v} V")
SPRINGS = {side: Variation(
    f"sec31-ls{side[0]}", f"sec31-spring-{side}", f"Sec. 3.1 ({side} spring)", f"initial {side} spring length",
    (f"spring_length_{side}_m",),
    tuple(getattr(TABLE2, f"spring_length_{side}_m") + k * SPRING_STEP_M for k in (-1, 0, 1)),
    "mm", f"{side} spring {{v}} mm", scale=1e3, spring_given=True) for side in ("upper", "lower")}


def _fig7_claims(wire: str) -> tuple[Claim, ...]:
    return (_sweep_claim(
        FIG7, wire, "fig7", "Fig. 7", "larger C_DF -> slower motion, heating and cooling",
        "C_DF mainly sets how quickly the finger reaches a position", ("rise90_s", "return90_s", "range_deg"),
        lambda v: (f"C_DF = {nums(v['value'], 'g')} N m s: 90% of range at {nums(v['rise90_s'])} s; "
                   f"90% of return in {nums(v['return90_s'])} s; range {nums(v['range_deg'], '.1f')} deg"),
        (Check("90% of the range reached later as C_DF increases", lambda v: increasing(v["rise90_s"])),
         Check("90% of the return later as C_DF increases", lambda v: increasing(v["return90_s"])),
         Check(f"the ranges agree within {RANGE_AGREEMENT:.0%} (C_DF acts on speed only)",
               lambda v: spread(v["range_deg"]) < RANGE_AGREEMENT * max(v["range_deg"])))),)


def _fig8_claims(wire: str) -> tuple[Claim, ...]:
    return (
        _sweep_claim(
            FIG8, wire, "fig8a", "Fig. 8(a)", "lower h0 -> larger range and earlier start of motion",
            "range and start ordered by h0 (lower h0 better)", ("range_deg", "start_s", "still_moving_deg_s"),
            lambda v: (f"h0 = {nums(v['value'], 'g')}: range {nums(v['range_deg'], '.1f')} deg; "
                       f"start {nums(v['start_s'])} s"),
            (Check("the range decreases as h0 increases", lambda v: decreasing(v["range_deg"])),
             Check("the motion starts later as h0 increases", lambda v: increasing(v["start_s"])),
             Check(f"every variant at its full range (< {STILL_DEG_S:g} deg/s) when the voltage is removed",
                   lambda v: all(x < STILL_DEG_S for x in v["still_moving_deg_s"])))),
        _sweep_claim(
            FIG8, wire, "fig8b", "Fig. 8(b)", "h0 mainly sets how quickly the joint goes back",
            "return speed depends on h0", ("return90_s",),
            lambda v: f"h0 = {nums(v['value'], 'g')}: 90% of the return in {nums(v['return90_s'])} s",
            (Check("90% of the return sooner as h0 increases", lambda v: decreasing(v["return90_s"])),),
            note="lower h0: slower cooling; the larger range also has further to return"),
    )


def _h2_measure(runs: list) -> dict:
    h2 = by_value("range_deg", "start_s")([r for r in runs if r.scenario.group == H2.group])
    h0 = [r.derived["range_deg"] for r in runs if r.scenario.group == FIG8.group]
    h2["h0_spread_deg"] = spread(h0) if len(h0) >= 2 else None
    return h2


def _h2_claims(wire: str) -> tuple[Claim, ...]:
    def shows(v):
        extra = "" if v["h0_spread_deg"] is None else (
            f"; range spread {spread(v['range_deg']):.1f} deg over this h2 range vs "
            f"{v['h0_spread_deg']:.1f} deg for h0 {min(FIG8.values):g}-{max(FIG8.values):g}")
        if v["h0_spread_deg"] is None:
            extra = "; h0's runs not selected, so the size of the effect is not compared"
        return (f"h2 = {nums(v['value'], 'g')}: range {nums(v['range_deg'], '.1f')} deg; "
                f"start {nums(v['start_s'])} s{extra}")

    return (Claim(
        key=f"h2-{wire}", figure="Sec. 3.1", statement=f"h2: similar qualitative effect to h0, smaller ({wire} wire)",
        paper="same ordering, smaller effect", scenarios=H2.names(wire), min_runs=2, also=FIG8.names(wire),
        measure=_h2_measure, shows=shows,
        checks=(Check("the range decreases as h2 increases", lambda v: decreasing(v["range_deg"])),
                Check("the motion starts later as h2 increases", lambda v: increasing(v["start_s"])),
                Check("h2 changes the range less than h0 does (not shown unless h0's runs ran too)",
                      lambda v: v["h0_spread_deg"] is not None and spread(v["range_deg"]) < v["h0_spread_deg"])),
        note=(f"same ordering as h0; the size of the effect depends on the range of h2 varied, which the "
              f"paper does not give (here {nums(H2_FACTORS, 'g')} x Table II's {TABLE2.h2_heating_W_m2K3:g})"),
        known_gap="the paper gives no h2 range; over +-50% of Table II's h2 the range moves more than over h0 60-70",
    ),)


def _ranges(runs: list) -> dict:
    out = {}
    for wire in WIRES:
        sel = sorted((r for r in runs if r.scenario.wire == wire), key=lambda r: r.scenario.value)
        out[wire] = [(r.scenario.value, r.scenario.unit, r.derived["range_deg"], r.derived["final_deg"]) for r in sel]
    return out


def _ranges_text(v: dict) -> str:
    return "range: " + "; ".join(
        f"{w} wire: " + ", ".join(f"{x:g} {u} -> {rng:.1f} deg" for x, u, rng, _ in rows)
        for w, rows in v.items() if rows)


def _spring_note(side: str):
    paper_mm = {s: getattr(TABLE2, f"spring_length_{s}_m") * 1e3 for s in ("upper", "lower")}

    def note(v: dict) -> str:
        text = "reported for completeness; the paper shows no result"
        if v["lower"]:
            text += ("; with spring_init = given the friction-free rest angle is not "
                     f"{TABLE2.theta0_deg:g} deg (after the flexion the joint settles at "
                     f"{nums([row[3] for row in v['lower']], '.1f')} deg)")
        if any(abs(x - paper_mm[side]) < 1e-9 and rng < START_OF_MOTION_DEG for x, _, rng, _ in v["upper"]):
            text += (f"; with the paper's own lengths ({paper_mm['upper']:g} / {paper_mm['lower']:g} mm) the "
                     f"upper wire at {TABLE2.V_H_V:g} V does not move the joint at all")
        return text
    return note


def _reported(v: Variation, what: str, note) -> Claim:
    return Claim(key=f"{v.group}-ranges", figure="Sec. 3.1", statement=f"{what} varied one at a time",
                 paper="varied (no figure)", scenarios=v.names("upper") + v.names("lower"), min_runs=1,
                 measure=_ranges, shows=_ranges_text, note=note)


def _figure(v: Variation, title: str, claims: tuple[Claim, ...], extra: str = "") -> Figure:
    volts = "" if v is VH else f"{TABLE2.V_H_V:g} V, "
    return Figure(v.group, f"{title} (open loop, {volts}Table II{extra})", figures.openloop, v.scenarios(), claims)


FIGURES = (
    _figure(FIG7, "Fig. 7: effect of the dynamic friction coefficient $C_{DF}$",
            _fig7_claims("upper") + _fig7_claims("lower")),
    _figure(FIG8, "Fig. 8: effect of $h_0$ in the heat convection model",
            _fig8_claims("upper") + _fig8_claims("lower")),
    _figure(H2, "Sec. 3.1: effect of $h_2$ in the heat convection model", _h2_claims("upper") + _h2_claims("lower")),
    _figure(VH, "Sec. 3.1: effect of the applied voltage $V_H$",
            (_reported(VH, "V_H", "reported for completeness; the paper shows no result"),)),
    *(_figure(SPRINGS[side], f"Sec. 3.1: effect of the initial {side} spring length",
              (_reported(SPRINGS[side], f"{side} spring", _spring_note(side)),), ", given springs")
      for side in ("upper", "lower")),
)

__all__ = ["FIGURES", "FIG7", "FIG8", "H2", "VH", "SPRINGS", "Variation", "STILL_DEG_S"]
