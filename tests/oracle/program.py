"""Open-loop drive programs and their stretches of constant drive (Eq. 12b, Fig. 6).

A program is ``"T:V_1[:V_2],..."``, one value per wire from time T on, read as volts
(``voltage``), fractions of the supply V_H switched at the PWM period (``duty``) or amperes
(``current``). A wire is commanded on while its level and duty are both positive; a duty
strictly between 0 and 1 is a PWM signal: the level for the first ``duty`` of every period
t_P, the low level for the rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

KINDS = ("voltage", "duty", "current")


@dataclass(frozen=True)
class Step:
    """From ``t`` on, wire i at ``levels[i]`` (V or A) for the fraction ``duties[i]`` of each period."""

    t: float
    levels: tuple[float, ...]
    duties: tuple[float, ...]

    @property
    def on(self) -> tuple[bool, ...]:
        """Each wire commanded on (its controller's heating phase, in open loop)."""
        return tuple(lv > 0.0 and d > 0.0 for lv, d in zip(self.levels, self.duties))


@dataclass(frozen=True)
class Stretch:
    """[t0, t1) with every wire's drive constant."""

    t0: float
    t1: float
    drives: tuple[float, ...]
    on: tuple[bool, ...]


def parse(text: str, kind: str, n_wires: int, V_H: float) -> list[Step]:
    """A program's steps (``kind``: voltage, duty or current)."""
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r} is not one of {', '.join(KINDS)}")
    steps = []
    for item in (s for s in text.split(",") if s.strip()):
        t, *values = (float(x) for x in item.split(":"))
        if len(values) != n_wires:
            raise ValueError(f"program step {item!r}: {len(values)} value(s), the mechanism has {n_wires} wire(s)")
        if kind == "duty":
            steps.append(Step(t, (V_H,) * n_wires, tuple(values)))
        else:
            steps.append(Step(t, tuple(values), tuple(1.0 if v > 0.0 else 0.0 for v in values)))
    return steps


def stretches(steps: list[Step], t_end: float, period: float, low: float):
    """The program as stretches of constant drive up to ``t_end`` (PWM edges resolved)."""
    for k, step in enumerate(steps):
        t0 = step.t
        t1 = min(steps[k + 1].t if k + 1 < len(steps) else t_end, t_end)
        if t1 <= t0:
            continue
        if all(d <= 0.0 or d >= 1.0 for d in step.duties):
            yield Stretch(t0, t1, tuple(_drive(step, i, 0.0, period, low) for i in range(len(step.levels))),
                          step.on)
            continue
        n = math.floor(t0 / period)
        while n * period < t1:
            ps = n * period
            edges = sorted({ps + d * period for d in step.duties if 0.0 < d < 1.0} | {ps + period})
            a = max(ps, t0)
            for b in edges:
                b = min(b, t1)
                if b > a:
                    mid = 0.5 * (a + b) - ps
                    yield Stretch(a, b, tuple(_drive(step, i, mid, period, low) for i in range(len(step.levels))),
                                  step.on)
                    a = b
            n += 1


def _drive(step: Step, i: int, t_in_period: float, period: float, low: float) -> float:
    """The drive of wire i at ``t_in_period`` into a PWM period (Fig. 6)."""
    d = step.duties[i]
    if not step.on[i]:
        return low
    if d >= 1.0 or (d > 0.0 and t_in_period < d * period):
        return step.levels[i]
    return low
