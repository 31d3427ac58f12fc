"""The controller bench's tasks: the paper's moves (Figs. 12, 13), its full cycle (Fig. 15), a
staircase and sine tracking, on the paper's joint and on the linear bias-spring actuator.

Every task is a target profile on one parameter set, run by every controller under every
strategy (:mod:`.runner`). The joint runs the set ``paper2010`` with the paper's friction
reading (:data:`smafinger.paper.scenario.PAPER_FRICTION`, as every Fig. 11-15 scenario);
targets are in the mechanism's user unit (deg for the joint, m for the slider).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..paper.fig15 import EXTEND_DEG, FLEX_DEG, on_reach
from ..paper.scenario import MOVE_S, PAPER_FRICTION
from ..paper.sec4 import FIG13_KINDS, KINDS, REST_DEG
from ..parameters import ParameterSet
from ..parameters import get as get_params
from ..values import one_or_many

#: sine references are sampled into profile segments this often [s]
SINE_SAMPLE_S = 0.05
#: sine tasks: periods simulated, of which the first ones are a transient left out of the fit
SINE_PERIODS = 4
SINE_SKIP_PERIODS = 1
#: a hold's last this-many seconds give its limit-cycle amplitude
HOLD_WINDOW_S = 2.0


@dataclass(frozen=True)
class Task:
    """One bench task: a profile on a parameter set.

    ``kind``: ``move`` (fixed-time targets), ``cycle`` (each target issued on reach; its time
    is the cycle time), ``staircase`` or ``sine`` (``frequency_hz``, ``amplitude``, ``offset``
    in user units).
    """

    name: str
    mechanism: str  #: ``joint`` or ``linear-bias-spring``
    kind: str
    profile: str
    t_end_s: float
    description: str
    frequency_hz: float | None = None
    amplitude: float | None = None
    offset: float | None = None
    overrides: tuple[str, ...] = field(default_factory=tuple)

    def params(self) -> ParameterSet:
        base = get_params(MECHANISM_SETS[self.mechanism])
        return base.with_overrides(list(self.overrides)) if self.overrides else base

    @property
    def fit_start_s(self) -> float:
        """Sine tasks: the fit (gain, phase, error) starts here, after the transient."""
        return SINE_SKIP_PERIODS / self.frequency_hz if self.frequency_hz else 0.0


#: mechanism -> the named parameter set its tasks run
MECHANISM_SETS = {"joint": "paper2010", "linear-bias-spring": "linear-bias-spring"}
#: the paper's friction reading as ``--set`` strings
_JOINT_OVERRIDES = tuple(PAPER_FRICTION.texts())


def _out_and_back(target: float, rest: float) -> str:
    return f"0:{target:g},{MOVE_S:g}:{rest:g}"


def sine_profile(offset: float, amplitude: float, frequency_hz: float, t_end_s: float) -> str:
    """q_F(t) = offset + amplitude sin(2 pi f t), held over every :data:`SINE_SAMPLE_S`."""
    n = int(round(t_end_s / SINE_SAMPLE_S))
    return ",".join(f"{k * SINE_SAMPLE_S:.6g}:{offset + amplitude * math.sin(2 * math.pi * frequency_hz * k * SINE_SAMPLE_S):.6g}"
                    for k in range(n))


def _staircase(levels: tuple[float, ...], step_s: float) -> str:
    return ",".join(f"{k * step_s:g}:{v:g}" for k, v in enumerate(levels))


def _sines(mechanism: str, offset: float, amplitude: float, unit: str, overrides=()) -> tuple[Task, ...]:
    out = []
    for f in SINE_FREQUENCIES_HZ:
        t_end = SINE_PERIODS / f
        out.append(Task(f"sine-{f:g}hz", mechanism, "sine", sine_profile(offset, amplitude, f, t_end), t_end,
                        f"sine tracking {offset:g} +/- {amplitude:g} {unit} at {f:g} Hz", f, amplitude, offset,
                        tuple(overrides)))
    return tuple(out)


#: sine frequencies: the gain at each gives the -3 dB bandwidth
SINE_FREQUENCIES_HZ = (0.02, 0.05, 0.1, 0.2, 0.5)

JOINT_STAIRS_DEG = (-35.0, -30.0, -25.0, -30.0, -35.0, -40.0, -45.0, -50.0, -55.0, -50.0, -45.0, -40.0)
SLIDER_STAIRS_M = (0.003, 0.006, 0.009, 0.012, 0.009, 0.006, 0.003, 0.0)
STAIR_S = 6.0
#: hold tasks: 12 deg either side of rest (the reach of Fig. 12's moves less 3 deg, inside the wires'
#: transformation range, where a resistance still moves with the angle)
HOLD_TARGETS_DEG = (("extension", -28.0), ("flexion", -52.0))
HOLD_TASK_S = 20.0

JOINT_TASKS: tuple[Task, ...] = (
    *(Task(f"fig12-{kind}", "joint", "move", _out_and_back(t, REST_DEG), 2.5 * MOVE_S,
           f"Fig. 12: {REST_DEG:g} -> {t:g} deg, held {MOVE_S:g} s, and back ({wire} actuator the agonist)",
           overrides=_JOINT_OVERRIDES) for kind, t, wire in KINDS),
    *(Task(f"fig13-{kind}", "joint", "move", _out_and_back(t, REST_DEG), 2.5 * MOVE_S,
           f"Fig. 13: {REST_DEG:g} -> {t:g} deg, held {MOVE_S:g} s, and back", overrides=_JOINT_OVERRIDES)
      for kind, t, _ in FIG13_KINDS if (kind, t) not in {(k, x) for k, x, _ in KINDS}),
    Task("fig15-cycle", "joint", "cycle", on_reach((EXTEND_DEG, FLEX_DEG, REST_DEG)), 60.0,
         f"Fig. 15: full cycle {REST_DEG:g} -> {EXTEND_DEG:g} -> {FLEX_DEG:g} -> {REST_DEG:g} deg, each target "
         "issued as soon as the previous one is reached", overrides=_JOINT_OVERRIDES),
    *(Task(f"hold-{kind}", "joint", "move", f"0:{t:g}", HOLD_TASK_S,
           f"hold: {REST_DEG:g} -> {t:g} deg, held {HOLD_TASK_S:g} s (the self-sensing goal: within 0.5 deg)",
           overrides=_JOINT_OVERRIDES) for kind, t in HOLD_TARGETS_DEG),
    Task("staircase", "joint", "staircase", _staircase((REST_DEG,) + JOINT_STAIRS_DEG, STAIR_S),
         STAIR_S * (len(JOINT_STAIRS_DEG) + 1), f"staircase of 5 deg steps every {STAIR_S:g} s over "
         f"{FLEX_DEG:g} .. {EXTEND_DEG:g} deg", overrides=_JOINT_OVERRIDES),
    *_sines("joint", REST_DEG, 10.0, "deg", _JOINT_OVERRIDES),
)

SLIDER_TASKS: tuple[Task, ...] = (
    Task("step-10mm", "linear-bias-spring", "move", _out_and_back(0.010, 0.0), 2.5 * MOVE_S,
         f"0 -> 10 mm, held {MOVE_S:g} s, and back (as Fig. 12 on the joint)"),
    Task("hold-8mm", "linear-bias-spring", "move", "0:0.008", HOLD_TASK_S, f"hold: 0 -> 8 mm, held {HOLD_TASK_S:g} s"),
    Task("cycle", "linear-bias-spring", "cycle", on_reach((0.006, 0.014, 0.0)), 60.0,
         "cycle 0 -> 6 -> 14 -> 0 mm, each target issued as soon as the previous one is reached"),
    Task("staircase", "linear-bias-spring", "staircase", _staircase((0.0,) + SLIDER_STAIRS_M, STAIR_S),
         STAIR_S * (len(SLIDER_STAIRS_M) + 1), f"staircase of 3 mm steps every {STAIR_S:g} s over 0 .. 12 mm"),
    *_sines("linear-bias-spring", 0.008, 0.004, "m"),
)

ALL_TASKS = JOINT_TASKS + SLIDER_TASKS
#: ``--quick``: a move on each mechanism and the fastest sine (a smoke run of every output)
QUICK_TASKS = (("joint", "fig12-extension"), ("linear-bias-spring", "step-10mm"),
               ("linear-bias-spring", "sine-0.5hz"))


def select_tasks(mechanisms: tuple[str, ...] = ("joint", "linear-bias-spring"),
                 names: tuple[str, ...] = (), quick: bool = False) -> tuple[Task, ...]:
    """The tasks of some mechanisms, optionally only those named (an unknown name is an error),
    or only the :data:`QUICK_TASKS` among them (one name is a tuple of one)."""
    mechanisms, names = one_or_many(mechanisms), one_or_many(names or ())  # None or (): every task
    unknown = sorted(set(mechanisms) - set(MECHANISM_SETS))
    if unknown:
        raise ValueError(f"mechanism {unknown[0]!r} is not one of {', '.join(MECHANISM_SETS)}")
    tasks = tuple(t for t in ALL_TASKS if t.mechanism in mechanisms)
    if names:
        known = {t.name for t in tasks}
        missing = [n for n in names if n not in known]
        if missing:
            raise ValueError(f"task {missing[0]!r} is not one of {', '.join(sorted(known))}")
        tasks = tuple(t for t in tasks if t.name in names)
    if quick:
        tasks = tuple(t for t in tasks if (t.mechanism, t.name) in QUICK_TASKS)
    return tasks
