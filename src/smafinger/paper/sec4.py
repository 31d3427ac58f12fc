"""Sec. 4: closed-loop moves with one actuator (Fig. 12) and the co-operative return
(Fig. 13), parameter set ``paper2010`` (Sec. 3.2 coefficients, PID of Sec. 4). Fig. 11 is in
:mod:`.fig11`.

The returns are reached at the scenarios' 1 ms step as at 0.1 ms (Fig. 12 within 2 ms, Fig. 13's
extension returns within 23 ms; report.md's step-size check): the rate-form stress law (Eq. 7b)
takes each sub-step's whole transformation increment
(:func:`smafinger.model.wire.transformation_catch_up`). Before that, the minor loops the PWM
drives under the memory rule (issue 10) made it drift at 1 ms and the returns ended 1-3 deg off
-40 deg. Fig. 12's returns are reached sooner than the paper's "almost 10 s" (a known gap).
"""

from __future__ import annotations

from ..metrics import SETTLE_BAND_DEG
from ..parameters import get as get_params
from . import figures
from .claim import Check, Claim, between, known
from .derived import MoveAndReturn
from .fmt import pct, secs
from .scenario import MOVE_S, PAPER_FRICTION, Figure, Scenario

PARAMS = "paper2010"
P2010 = get_params(PARAMS)
#: the rest position, where every move starts and returns [deg]
REST_DEG = P2010.theta0_deg
#: Fig. 12, the cooling phase lasts "almost 10 s": return reached / settled in these bands [s]
REACH_BAND_S = (8.0, 10.5)
SETTLE_TIME_BAND_S = (7.0, 11.0)
#: Fig. 12, "the deviations were small": overshoot below this [deg]
MOVE_OVERSHOOT_DEG = 1.0
PID = f"{P2010.K_P_per_rad:g}/{P2010.K_V_s_per_rad:g}/{P2010.K_I_per_rad_s:g}"
#: why Fig. 12's return claim is not met (the same at 1 ms and 0.1 ms)
RETURN_GAP = ("the passive returns reach -40 deg sooner than the paper's 'almost 10 s' (extension 6.5 s, flexion "
              "6.2 s); they settle within the settle band (8.5 s, 8.0 s)")


def _by_key(runs: list) -> dict:
    return {r.key: r for r in runs}


# ---------------------------------------------------------------------------------------
# Fig. 12: closed-loop moves with one actuator, and the return through its cooling phase
# ---------------------------------------------------------------------------------------
KINDS = (("extension", -25.0, "upper"), ("flexion", -55.0, "lower"))
FIG12 = tuple(Scenario(
    name=f"fig12-{kind}-v1", figure="Fig. 12",
    description=(f"Fig. 12, Sec. 4.1: closed-loop {kind} {REST_DEG:g} -> {target:g} deg with the {wire} "
                 f"actuator only (PID {PID}), held {MOVE_S:g} s, then back to {REST_DEG:g} deg through its "
                 f"cooling phase"),
    params=PARAMS, strategy="independent", profile=f"0:{target:g}:{wire},{MOVE_S:g}:{REST_DEG:g}:{wire}",
    t_end_s=2.5 * MOVE_S, overrides=PAPER_FRICTION, group="fig12", panel=kind,
    label=f"{kind} ({wire} actuator)", wire=wire, derive=MoveAndReturn()) for kind, target, wire in KINDS)


def _fig12_measure(runs: list) -> dict:
    r = _by_key(runs)
    return {s.panel: {**r[s.name].derived["return"], "wire": s.wire, "move": r[s.name].derived["move"]}
            for s in FIG12}


def _fig12_return_shows(v: dict) -> str:
    return "; ".join(
        f"{k}: reached in {secs(x['reached_s'])}, settled within {SETTLE_BAND_DEG:g} deg in "
        f"{secs(x['settle_s'])}, wire back to martensite after {secs(x['martensite_' + x['wire'] + '_s'])}, "
        f"at {x['final_deg']:.2f} deg when the run ends" for k, x in v.items())


FIG12_CLAIMS = (
    Claim(key="fig12-return", figure="Fig. 12", statement="the return through the cooling phase (one actuator) lasts",
          paper="almost 10 s", scenarios=tuple(s.name for s in FIG12), measure=_fig12_measure,
          shows=_fig12_return_shows,
          checks=(Check(f"both returns reach {REST_DEG:g} deg in {REACH_BAND_S[0]:g}-{REACH_BAND_S[1]:g} s",
                        lambda v: all(between(x["reached_s"], *REACH_BAND_S) for x in v.values())),),
          fallback=(Check(f"both settle within {SETTLE_BAND_DEG:g} deg in "
                          f"{SETTLE_TIME_BAND_S[0]:g}-{SETTLE_TIME_BAND_S[1]:g} s",
                          lambda v: all(between(x["settle_s"], *SETTLE_TIME_BAND_S) for x in v.values())),),
          known_gap=RETURN_GAP),
    Claim(key="fig12-moves", figure="Fig. 12", statement=f"+/-15 deg closed-loop moves with gains {PID}",
          paper="small deviations over the tested range", scenarios=tuple(s.name for s in FIG12),
          measure=_fig12_measure,
          shows=lambda v: "; ".join(
              f"{REST_DEG:g} -> {x['move']['target_deg']:g}: reached in {secs(x['move']['reached_s'])}, "
              f"overshoot {x['move']['overshoot_deg']:.2f} deg" for x in v.values()),
          checks=(Check(f"both moves reach their target, overshoot < {MOVE_OVERSHOOT_DEG:g} deg",
                        lambda v: all(x["move"]["reached_s"] is not None
                                      and x["move"]["overshoot_deg"] < MOVE_OVERSHOOT_DEG for x in v.values())),)),
)


# ---------------------------------------------------------------------------------------
# Fig. 13: the return with the agonist only (Case 1) or both actuators (Case 2)
# ---------------------------------------------------------------------------------------
def _fig13(kind: str, target: float, wire: str, case: int) -> Scenario:
    if case == 1:
        what = (f"Fig. 13 Case 1, Sec. 4.2: {kind} to {target:g} deg with the {wire} actuator, held {MOVE_S:g} s, "
                f"then its cooling phase back to {REST_DEG:g} deg with the agonist only (the antagonist a "
                f"passive bias spring)")
        strategy, profile = "independent", f"0:{target:g}:{wire},{MOVE_S:g}:{REST_DEG:g}:{wire}"
    else:
        what = (f"Fig. 13 Case 2, Sec. 4.2: {kind} to {target:g} deg, held {MOVE_S:g} s, then back to "
                f"{REST_DEG:g} deg with both actuators (co-operative: the antagonist heats as soon as the "
                f"joint passes the target)")
        strategy, profile = "cooperative", f"0:{target:g},{MOVE_S:g}:{REST_DEG:g}"
    return Scenario(name=f"fig13-{kind}-case{case}-v1", figure="Fig. 13", description=what, params=PARAMS,
                    strategy=strategy, profile=profile, t_end_s=2.5 * MOVE_S, overrides=PAPER_FRICTION,
                    group="fig13", panel=kind, wire=wire, derive=MoveAndReturn(),
                    label="Case 1: agonist only" if case == 1 else "Case 2: co-operative")


FIG13_KINDS = (("extension", -30.0, "upper"), ("flexion", -55.0, "lower"))
FIG13 = tuple(_fig13(k, t, w, case) for k, t, w in FIG13_KINDS for case in (1, 2))


#: the antagonist "pulls" once its martensite fraction falls below this (it has begun to transform)
PULLS_BELOW_XI = 0.99


def _fig13_claim(kind: str, target: float, antagonist: str) -> Claim:
    names = (f"fig13-{kind}-case1-v1", f"fig13-{kind}-case2-v1")

    def measure(runs: list) -> dict:
        r = _by_key(runs)
        ret = [r[n].derived["return"] for n in names]
        case2 = r[names[1]]
        return {"case1": ret[0]["reached_s"], "case2": ret[1]["reached_s"],
                "final1_deg": ret[0]["final_deg"], "final2_deg": ret[1]["final_deg"],
                "antagonist_xi_min": float(case2.result.signal(f"xi_{antagonist}").min()),
                "antagonist_peak_C": case2.summary["peak_temperature_C"][antagonist],
                "A_S0_C": case2.spec.params.A_S0_C}

    def note(v: dict) -> str:
        pulls = (f"the {antagonist} wire (the antagonist) peaks at {v['antagonist_peak_C']:.1f} °C against its A_S0 "
                 f"{v['A_S0_C']:g} °C, xi down to {v['antagonist_xi_min']:.3f}")
        if known(v["case1"], v["case2"]):
            return f"{pct(1 - v['case2'] / v['case1'])} faster; {pulls}"
        return (f"when the run ends the joint is at {v['final1_deg']:.2f} deg (Case 1) and {v['final2_deg']:.2f} deg "
                f"(Case 2); {pulls}")

    return Claim(
        key=f"fig13-{kind}", figure="Fig. 13",
        statement=(f"{kind}: return from {target:g} to {REST_DEG:g} deg faster with the antagonist (Case 2) than "
                   "with the agonist only (Case 1)"),
        paper="Case 2 clearly faster", scenarios=names, measure=measure,
        shows=lambda v: f"Case 1 {secs(v['case1'])}, Case 2 {secs(v['case2'])}",
        checks=(Check("Case 2 back at the rest position sooner than Case 1",
                      lambda v: known(v["case1"], v["case2"]) and v["case2"] < v["case1"]),
                Check(f"in Case 2 the antagonist transforms (xi below {PULLS_BELOW_XI:g}), so it pulls",
                      lambda v: v["antagonist_xi_min"] < PULLS_BELOW_XI)),
        note=note,
        known_gap=("the antagonist stays below its austenite start and adds no force: Case 2 is faster through the "
                   "damping rule (damping_switch = heating-phase: C_DF 0.03 Nms while a wire is enabled in its heating "
                   "phase, 0.09 in Case 1's passive return); Case 1 run at 0.03 returns as fast as Case 2 "
                   "(docs/reproduce.md)"))


#: Fig. 13's claims; the flexion's Case 1 is the Fig. 12 flexion run
FIG13_CLAIMS = tuple(_fig13_claim(kind, target, "lower" if wire == "upper" else "upper")
                     for kind, target, wire in FIG13_KINDS)

FIGURES = (
    Figure("fig12", f"Fig. 12: closed-loop moves with one actuator (PID {PID}) and the return through its "
           "cooling phase", figures.moves, FIG12, FIG12_CLAIMS),
    Figure("fig13", "Fig. 13: cooling phase with the agonist only (Case 1) vs co-operative (Case 2)",
           figures.returns, FIG13, FIG13_CLAIMS),
)

__all__ = ["FIGURES", "FIG12", "FIG13", "REST_DEG", "MOVE_S", "PARAMS", "PID", "RETURN_GAP"]
