"""A named scenario (one run behind a figure), a figure (its runs, layout and claims), and
the readings the paper's scenarios share.

Shared readings (the long form is in ``docs/reproduce.md``):

- Parameter sets: ``paper2010-table2`` (Table II) for the open-loop parametric analysis of
  Sec. 3.1; ``paper2010`` (the coefficients of Sec. 3.2, PID of Sec. 4) for Figs. 11-15.
- Friction (:data:`PAPER_FRICTION`): ``friction_sticking = initial-only``. Sec. 3.1: "any
  stick-slip effects were neglected ... the friction is purely viscous after the onset of
  the motion".
- Open loop (Sec. 3.1): the set's V_H on one wire for :data:`OPEN_LOOP_ON_S`, then 0 V as
  long again.
- Closed-loop moves of Figs. 11-13 hold each target :data:`MOVE_S`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

from ..engine.run import DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_OUTPUT_S, DEFAULT_PWM, RunSpec, make_spec
from ..parameters import ParameterSet
from ..parameters import get as get_params
from .claim import Claim
from .derived import Derivation
from .overrides import Overrides

#: the friction reading of Sec. 3.1, applied to every scenario of the paper
PAPER_FRICTION = Overrides.of(friction_sticking="initial-only")
#: open loop: voltage on for this long, then off for as long again [s]
OPEN_LOOP_ON_S = 20.0
#: closed-loop moves of Figs. 11-13: time each target is held [s]
MOVE_S = 10.0
#: in a scenario's voltage program, the set's V_H, resolved after every override (a ``--set V_H_V``
#: included): ``"0:V_H:0,20:0:0"``
V_H = "V_H"


@dataclass(frozen=True)
class Scenario:
    """One named simulation: parameter set and overrides, strategy, profile, duration.

    ``group`` is the output figure the run belongs to, ``panel`` its place there
    (e.g. ``"extension"``), ``label`` its legend; ``wire`` is the heated (agonist) wire,
    ``value`` the varied value (open-loop variations) in ``unit``; ``derive`` names the
    figure metrics its claims read.
    """

    name: str
    figure: str
    description: str
    params: str
    strategy: str
    t_end_s: float
    profile: str | None = None
    voltage: str | None = None
    overrides: Overrides = field(default_factory=Overrides)
    group: str = ""
    panel: str = ""
    label: str = ""
    wire: str | None = None
    value: float | None = None
    unit: str = ""
    derive: Derivation | None = None

    def parameters(self, overrides: Overrides | Iterable[str] = ()) -> ParameterSet:
        """The scenario's parameter set, with its own overrides and then ``overrides``."""
        return self.overrides.then(Overrides.coerce(overrides)).apply(get_params(self.params))

    def spec(self, overrides: Overrides | Iterable[str] = (), dt_s: float | None = None,
             method: str | None = None, output_interval_s: float = DEFAULT_OUTPUT_S,
             tol_deg: float | None = None, hold_s: float | None = None, *, profile: str | None = None,
             t_end_s: float | None = None, independent_wait: bool | None = None,
             strategy: str | None = None, pwm: str | None = None) -> RunSpec:
        """A validated :class:`~smafinger.engine.run.RunSpec` of this scenario.

        ``overrides`` (an :class:`Overrides` or ``NAME=VALUE`` strings) apply after the
        scenario's own; the other arguments replace the scenario's run settings (``None``:
        the scenario's, or the engine's default). The paper's scenarios run at the reference
        numerics (rk4, 1 ms, exact PWM: their figures show the PWM-resolved temperatures and the
        golden record holds their bits), not at a run's long-step default.
        """
        dt_s = DEFAULT_DT_S if dt_s is None else dt_s
        method = DEFAULT_METHOD if method is None else method
        pwm = DEFAULT_PWM if pwm is None else pwm
        given = dict(profile=profile, t_end_s=t_end_s, independent_wait=independent_wait,
                     strategy=strategy, tol_deg=tol_deg, hold_s=hold_s)
        ov = (self.overrides.then(Overrides.coerce(overrides))
              .then(Overrides.of(**{k: v for k, v in given.items() if v is not None})))
        run = {"strategy": self.strategy, "profile": self.profile, "t_end_s": self.t_end_s}
        run.update(ov.settings())
        p = ov.apply(get_params(self.params))
        voltage = None if self.voltage is None else self.voltage.replace(V_H, repr(p.V_H_V))
        return make_spec(p, voltage=voltage, dt_s=dt_s, method=method, output_interval_s=output_interval_s,
                         pwm=pwm, **run)

    def definition(self) -> dict:
        """The scenario as plain values (for ``summary.json``)."""
        return {"figure": self.figure, "description": self.description, "params": self.params,
                "overrides": list(self.overrides.texts()), "strategy": self.strategy,
                "profile": self.profile, "voltage": self.voltage, "t_end_s": self.t_end_s}

    def definition_sha256(self) -> str:
        """SHA-256 of what the name stands for: the :meth:`definition` but its words (figure,
        description). A changed definition needs a new name (``-v2``); ``tests/golden/
        scenario_definitions.json`` records every name's and a test holds them."""
        import hashlib
        import json

        d = {k: v for k, v in self.definition().items() if k not in ("figure", "description")}
        return hashlib.sha256(json.dumps(d, sort_keys=True).encode()).hexdigest()


#: ``plot(runs, title, path)``: draws a figure's runs into ``path`` (see :mod:`.figures`)
Plot = Callable[[list, str, Path], None]


@dataclass(frozen=True)
class Figure:
    """An output figure: its runs, how it is drawn, and the claims it supports."""

    key: str
    title: str
    plot: Plot
    scenarios: tuple[Scenario, ...]
    claims: tuple[Claim, ...] = ()

    def __post_init__(self) -> None:
        for s in self.scenarios:
            if s.group != self.key:
                raise ValueError(f"scenario {s.name!r}: group {s.group!r} is not figure {self.key!r}")


__all__ = ["Scenario", "Figure", "PAPER_FRICTION", "OPEN_LOOP_ON_S", "MOVE_S", "V_H"]
