"""The controllers the bench compares, per mechanism: the paper's PWM-PID as published, and the
others with values tuned by ``smafinger tune`` (:mod:`.tune`), each with its provenance.

A bench entry is a name (the ``controller`` column of the bench's table) for a controller of
:mod:`smafinger.control.params` with some of its fields set. ``pid`` is the paper's PWM-PID
with the set's own gains (Sec. 4: 3000, 3000, 50 on the joint); ``pid-tuned`` the same law with
tuned gains, to tell what the gains alone buy from what an architecture buys. The
self-sensing controller is calibrated for the bench's parameter set when the bench starts
(:func:`smafinger.control.calibration.calibrate`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..control.params import CONTROLLERS, ControllerParameters
from ..parameters import ParameterSet


@dataclass(frozen=True)
class Entry:
    controller: str  #: a label of smafinger.control.params.CONTROLLERS
    values: dict = field(default_factory=dict)  #: per mechanism: {field: value}
    provenance: dict = field(default_factory=dict)  #: per mechanism: how the values were obtained
    #: a tuned entry runs only on the mechanisms it has values for
    tuned: bool = False


#: ``pid-tuned`` on the joint (see its provenance)
PID_TUNED_JOINT = {"K_P_per_q": 2365.0, "K_V_s_per_q": 1311.0, "K_I_per_q_s": 13.65}

_TUNE = ("smafinger tune {c} -t fig15-cycle -m joint -s cooperative --budget {b} --popsize 10 --seed 1 {p} "
         "(CMA-ES; the paper's PID's peak temperature, 103.1 degC, a hard limit)")
_PID_BOX = "--param K_P_per_q=500:30000:log --param K_V_s_per_q=100:10000:log --param K_I_per_q_s=5:1000:log"

#: the bench's controllers, in the order of its tables (values: see each entry's provenance)
ENTRIES: dict[str, Entry] = {
    "pid": Entry("pid"),
    "pid-tuned": Entry("pid", {"joint": PID_TUNED_JOINT}, {"joint": _TUNE.format(c="pid", b=40, p=_PID_BOX) + ", rounded to 4 digits"},
                       tuned=True),
    "fuzzy-pid": Entry("fuzzy-pid"),
    "fuzzy-pid-tuned": Entry(
        "fuzzy-pid",
        {"joint": {"K_P_min_per_q": 464.5, "K_P_max_per_q": 1172.0, "K_V_min_s_per_q": 756.5,
                   "K_V_max_s_per_q": 7218.0, "e_span_q": 0.4915, "de_span_q_s": 0.9953}},
        {"joint": _TUNE.format(c="fuzzy-pid", b=40, p="(its default box)") + ", rounded to 4 digits"}, tuned=True),
    "sliding-mode": Entry("sliding-mode"),
    "sliding-mode-tuned": Entry(
        "sliding-mode",
        {"joint": {"lambda_per_s": 1.56, "lambda_I_per_s2": 0.007003, "phi_q_per_s": 0.01546, "K_pct": 98.58}},
        {"joint": _TUNE.format(c="sliding-mode", b=40, p="(its default box)") + ", rounded to 4 digits"},
        tuned=True),
    "rapid-heating": Entry("rapid-heating"),
    "rapid-heating-tuned": Entry(
        "rapid-heating",
        {"joint": {"K_P_per_q": 3845.0, "K_V_s_per_q": 2567.0, "K_I_per_q_s": 41.85, "boost_V": 9.568,
                   "boost_until_C": 51.3, "preheat_C": 58.47}},
        {"joint": _TUNE.format(c="rapid-heating", b=60, p=_PID_BOX + " --param boost_V=5:12 --param "
                               "boost_until_C=40:80 --param preheat_C=20:60") + ", rounded to 4 digits"},
        tuned=True),
    "resistance": Entry("resistance"),
}
BENCH_CONTROLLERS = tuple(ENTRIES)
#: ``--quick``: the paper's law and one of the chain's (two compiled loops per mechanism)
QUICK_CONTROLLERS = ("pid", "sliding-mode")


def bench_controller(name: str, p: ParameterSet) -> ControllerParameters | None:
    """Bench entry ``name`` on set ``p`` (its tuned values for ``p``'s mechanism; calibrated if
    self-sensing); ``None`` for a tuned entry without values for that mechanism."""
    if name not in ENTRIES:
        raise ValueError(f"controller {name!r} is not one of {', '.join(ENTRIES)}")
    e = ENTRIES[name]
    if e.tuned and p.mechanism not in e.values:
        return None
    return CONTROLLERS[e.controller](**e.values.get(p.mechanism, {})).prepared(p)
