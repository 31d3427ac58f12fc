"""The authors' public 2020 Simulink model: its two example profiles (MODEL-NOTES); and the
claim every run is checked against, the interlock of Sec. 2.6."""

from __future__ import annotations

from . import figures
from .claim import Check, Claim
from .derived import Cycle
from .scenario import Figure, Scenario

PARAMS = "authors2020"


def _segments(runs: list) -> dict:
    return {"segments": runs[0].summary["segments"]}


def _shows(v: dict) -> str:
    return "; ".join(f"{s['target_deg']:g} deg ({s['enable']}) from {s['start_s']:g} s: "
                     + ("not reached" if s["reached_s"] is None else f"reached in {s['reached_s']:.2f} s")
                     for s in v["segments"])


def _profile(number: int, description: str, profile: str) -> tuple[Scenario, Claim]:
    s = Scenario(name=f"authors2020-profile{number}-v1", figure=f"authors' 2020 model, profile {number}",
                 description=description, params=PARAMS, strategy="independent", profile=profile,
                 t_end_s=20.0, group="authors2020", panel=str(number), label=f"profile {number}",
                 derive=Cycle())
    c = Claim(key=f"authors2020-profile{number}", figure="authors' 2020 model",
              statement=f"profile {number} runs and reaches its targets",
              paper="targets reached (the model's example results)", scenarios=(s.name,), measure=_segments,
              shows=_shows,
              checks=(Check("every segment with an actuator enabled reaches its target",
                            lambda v: all(x["reached_s"] is not None for x in v["segments"] if x["enable"] != "none")),),
              note=lambda v: ("a segment with enable 'none' (both off) is a cool-down, not a target"
                              if any(x["enable"] == "none" for x in v["segments"]) else ""))
    return s, c


PROFILES = (
    _profile(1, ("authors' 2020 model (ProfileType = 1): -25 deg with the upper actuator (0-5 s), both off to "
                 "cool down (5-10 s), -30 deg with the upper actuator (10-20 s)"), "0:-25:upper,5:-40:none,10:-30:upper"),
    _profile(2, ("authors' 2020 model (ProfileType = 2): -25 deg with the upper actuator (0-5 s), then -55 deg "
                 "with both actuators enabled (5-20 s)"), "0:-25:upper,5:-55:both"),
)

FIGURES = (Figure("authors2020", "Authors' 2020 Simulink model: example profiles 1 and 2 (authors2020 parameters)",
                  figures.profiles, tuple(s for s, _ in PROFILES), tuple(c for _, c in PROFILES)),)


def _violations(runs: list) -> dict:
    return {"violations": {r.key: r.summary["interlock_violations"] for r in runs}}


#: Sec. 2.6: the interlock, checked on every scenario run
INTERLOCK = Claim(
    key="interlock", figure="Sec. 2.6", statement="both wires are never heated at once", paper="must never happen",
    scenarios=(), min_runs=1, measure=_violations,
    shows=lambda v: f"{sum(v['violations'].values())} interlock violations in {len(v['violations'])} runs",
    checks=(Check("no interlock violation in any run", lambda v: not any(v["violations"].values())),),
    note=lambda v: "; ".join(x for x in (
        ", ".join(f"{k}: {n}" for k, n in v["violations"].items() if n),
        "it holds by construction (opposing wires get clamp(u) and clamp(-u) of one PID output; an open-loop program "
        "that would heat both is refused): the count is the engine's own check of the drives at every sub-step, "
        "there to catch a regression") if x))

__all__ = ["FIGURES", "INTERLOCK"]
