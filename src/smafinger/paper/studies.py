"""Studies: named scenarios re-run with one change each (a *variant*), as data.

A :class:`Study` lists scenarios and the variants they are re-run under; each (variant,
scenario) is one run, keyed ``{study}:{variant}:{scenario}``, and the variant
:data:`AS_SPECIFIED` is the scenario's own run. A variant changes parameters or run settings
(:class:`~.overrides.Overrides`) and may refine the step; ``only`` restricts it to some of the
study's scenarios. The report's tables (:mod:`.issue10`) read them.

- :data:`HYSTERESIS`: Figs. 12, 13 and 15 before issue 10's hysteresis change (smafinger 0.1's
  dead band) and after it at a ten times finer step (is the 1 ms step converged?).
- :data:`CYCLE`: the Fig. 15 cycles under each damping rule and two thermal readings.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Mapping

from ..engine.run import RunSpec
from .derived import Derivation, Run
from .fig10 import CASING
from .fig11 import WARM_C
from .fig15 import REACH, REACH_V1, SCHEDULE, SCHEDULE_V1
from .overrides import Overrides
from .scenarios import get
from .sec4 import FIG12, FIG13, P2010

#: the finer step of the step-size check [s] (the scenarios use 1 ms)
FINE_DT_S = 1e-4


@dataclass(frozen=True)
class Variant:
    """One change to a study's runs: ``overrides`` and, if given, the step ``dt_s``."""

    key: str
    label: str
    topic: str
    overrides: Overrides = Overrides()
    dt_s: float | None = None
    only: tuple[str, ...] | None = None
    short: str = ""  #: its name in sentences (default: the key)

    @property
    def name(self) -> str:
        return self.short or self.key

    def applies(self, name: str) -> bool:
        return self.only is None or name in self.only

    def spec(self, name: str) -> RunSpec:
        kw = {} if self.dt_s is None else {"dt_s": self.dt_s}
        return get(name).spec(self.overrides, **kw)


AS_SPECIFIED = Variant("as-specified", "as specified (the scenario's own run)", "baseline", short="as specified")


@dataclass(frozen=True)
class Study:
    """Scenarios and the variants they are re-run under."""

    key: str
    scenarios: tuple[str, ...]
    variants: tuple[Variant, ...]

    def variant(self, key: str) -> Variant:
        for v in (AS_SPECIFIED, *self.variants):
            if v.key == key:
                return v
        raise ValueError(f"study {self.key!r}: unknown variant {key!r}")

    def run_key(self, variant: Variant, name: str) -> str:
        return name if variant is AS_SPECIFIED else f"{self.key}:{variant.key}:{name}"

    def tasks(self, names: Iterable[str] | None = None) -> list[tuple[str, RunSpec]]:
        """``(key, spec)`` of every variant's run of the study's scenarios (of ``names`` only, if given)."""
        chosen = set(self.scenarios if names is None else names)
        return [(self.run_key(v, n), v.spec(n)) for v in self.variants for n in self.scenarios
                if n in chosen and v.applies(n)]

    def derivations(self) -> dict[str, Derivation | None]:
        """The figure metrics of each run: its scenario's."""
        return {self.run_key(v, n): get(n).derive for v in self.variants for n in self.scenarios if v.applies(n)}

    def run(self, runs: Mapping[str, Run], variant: Variant, name: str) -> Run | None:
        """The finished run of ``variant`` on scenario ``name`` (``None``: not run or failed)."""
        r = runs.get(self.run_key(variant, name))
        return r if r is not None and r.ok else None


_FIG15 = tuple(dict.fromkeys([*REACH.values(), *REACH_V1.values(), *SCHEDULE.values(), *SCHEDULE_V1.values()]))
_FIG12 = tuple(s.name for s in FIG12)
_FIG13 = tuple(s.name for s in FIG13)
_FINE = _FIG12 + _FIG13 + tuple(dict.fromkeys([*REACH.values(), *SCHEDULE.values()]))

DEADBAND = Variant("deadband", "before issue 10: smafinger 0.1's dead-band hysteresis (hysteresis = deadband)",
                   "hysteresis", Overrides.of(hysteresis="deadband"), short="dead band (before the change)")
FINE_STEP = Variant("dt0.1ms", f"after, at a {FINE_DT_S * 1e3:g} ms step (the scenarios use 1 ms)", "step",
                    dt_s=FINE_DT_S, only=_FINE, short=f"{FINE_DT_S * 1e3:g} ms step")
ALGEBRAIC = Variant("algebraic", "after, with the algebraic stress law (stress_law = algebraic, as in the authors' "
                    "2020 model) instead of Eq. (7b)'s rate form", "stress law", Overrides.of(stress_law="algebraic"),
                    only=_FIG12, short="algebraic stress law")

HYSTERESIS = Study("hyst", _FIG12 + _FIG13 + _FIG15, (DEADBAND, FINE_STEP, ALGEBRAIC))

#: the paper2010 set's two C_DF values; its rule (heating-phase switching) is the scenarios' own runs
C_DF = {"heating": P2010.C_DF_heating_Nms, "cooling": P2010.C_DF_cooling_Nms}
#: one C_DF throughout, the heating or the cooling value, set through the parameters (``damping_switch =
#: heating-value`` gives the first of the two; tests/test_paper_claims.py checks they are the same run)
ONE_CDF = {k: Overrides.of(**{f"C_DF_{'cooling' if k == 'heating' else 'heating'}_Nms": v}) for k, v in C_DF.items()}


def _one_cdf(which: str, dt_s: float | None = None) -> Variant:
    other = "cooling" if which == "heating" else "heating"
    step = "" if dt_s is None else f", at a {dt_s * 1e3:g} ms step"
    return Variant(f"cdf-{which}" + ("" if dt_s is None else f"-{dt_s * 1e3:g}ms"),
                   f"one C_DF throughout: its {which} value {C_DF[which]:g} N m s/rad (C_DF_{other}_Nms = "
                   f"{C_DF[which]:g}){step}", "damping", ONE_CDF[which], dt_s=dt_s,
                   short=f"one C_DF {C_DF[which]:g}" + ("" if dt_s is None else f" at {dt_s * 1e3:g} ms"))


CYCLE = Study("cycle", tuple(dict.fromkeys([*REACH.values(), *SCHEDULE.values()])), (
    Variant("enabled", "C_DF's heating value while any actuator is enabled (damping_switch = enabled, the authors' "
            "2020 model)", "damping", Overrides.of(damping_switch="enabled"), short="enable rule"),
    _one_cdf("heating"), _one_cdf("cooling"), _one_cdf("heating", FINE_DT_S), _one_cdf("cooling", FINE_DT_S),
    Variant("two-node", "two-node thermal model with Fig. 10(a)'s casing (the casing air warms up over the cycle, "
            "Sec. 4.1)", "thermal", CASING.then(Overrides.of(thermal_model="two-node")), short="two-node casing"),
    Variant("tamb60", f"ambient and initial temperature {WARM_C:g} degC (the authors' 2020 model)", "thermal",
            Overrides.of(T_amb_C=WARM_C, T_init_C=WARM_C), short=f"{WARM_C:g} degC ambient"),
))

STUDIES = (HYSTERESIS, CYCLE)


def tasks(names: Iterable[str] | None = None) -> list[tuple[str, RunSpec]]:
    """Every study's runs (of the scenarios ``names`` only, if given)."""
    return [t for s in STUDIES for t in s.tasks(names)]


def derivations() -> dict[str, Derivation | None]:
    out: dict[str, Derivation | None] = {}
    for s in STUDIES:
        out.update(s.derivations())
    return out


__all__ = ["Variant", "Study", "AS_SPECIFIED", "HYSTERESIS", "CYCLE", "STUDIES", "DEADBAND", "FINE_STEP", "ALGEBRAIC",
           "FINE_DT_S", "C_DF", "ONE_CDF", "tasks", "derivations"]
