"""Model options: the choices the paper leaves open, kept apart from parameter values.

Each option is an :class:`Option` (an ``IntEnum``): users spell its members in kebab-case
(``"initial-only"``), the compiled code compares the members themselves
(``options.friction_sticking == FrictionSticking.INITIAL_ONLY``). A set of options is a
:class:`ModelOptions`; each named parameter set carries the options its source used, and a
user overrides one like a parameter (``--set friction_sticking=restick``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields
from enum import IntEnum
from typing import Any, NamedTuple

from .errors import ParameterError


class OptionError(ParameterError):
    """An option value is not one of the option's members."""


class Option(IntEnum):
    """An integer enum whose members users spell in kebab-case."""

    @property
    def label(self) -> str:
        return self.name.lower().replace("_", "-")

    def __str__(self) -> str:  # what TOML files and summaries show
        return self.label

    def __eq__(self, other: object) -> bool:
        # equal to its kebab-case label too: p.stress_law == "algebraic" keeps working
        if isinstance(other, str):
            return self.label == other
        return int.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    __hash__ = IntEnum.__hash__

    @classmethod
    def labels(cls) -> list[str]:
        return [m.label for m in cls]

    @classmethod
    def parse(cls, name: str, value: Any) -> "Option":
        """The member spelled ``value`` (a member, or its kebab-case label)."""
        if isinstance(value, cls):
            return value
        if isinstance(value, str):
            for m in cls:
                if m.label == value.strip().lower():
                    return m
        raise OptionError(f"{name} = {value!r} is not one of {', '.join(cls.labels())}")


class SpringInit(Option):
    """Initial spring elongations of the joint's tendons (MODEL-NOTES, "Springs and slack")."""

    GIVEN = 0  #: both initial spring lengths as set
    EQUILIBRIUM = 1  #: lower as set, upper from the friction-free moment balance at theta0


class StressLaw(Option):
    """Constitutive law of a wire (Eqs. 7-8)."""

    RATE = 0  #: integrate the rate form, Eq. (7b)
    ALGEBRAIC = 1  #: sigma = D_eq (eps - eps_R xi), solved with xi (authors' 2020 model)


class FrictionSticking(Option):
    """When the mechanism sticks (Eq. 2)."""

    RESTICK = 0  #: whenever it comes to rest with its net load below the static friction
    INITIAL_ONLY = 1  #: only while its velocity is exactly zero, i.e. at the start (Sec. 3.1)


class DampingSwitch(Option):
    """Which viscous coefficient applies (Sec. 3.2: heating and cooling values)."""

    HEATING_PHASE = 0  #: heating value while any wire is in its controller's heating phase
    ENABLED = 1  #: heating value while any wire is enabled (authors' 2020 model)
    HEATING_VALUE = 2  #: the heating value throughout (no switching)


class Hysteresis(Option):
    """Minor hysteresis loops of the phase kinetics (Eqs. 9-10; MODEL-NOTES, docs/hysteresis.md)."""

    MEMORY = 0  #: return-point memory (a stack of reversal points): the default
    AUTHORS2020 = 1  #: the authors' 2020 model: branch from the sign of dT/dt, start re-solved
    DEADBAND = 2  #: smafinger 0.1: the authors' rule with a reversal of minor_loop_reversal_C


class ThermalModel(Option):
    """Heat transfer of a wire (Eq. 11; Sec. 3.2 and Fig. 10a)."""

    SINGLE_NODE = 0  #: Eq. (11): the wire exchanges heat with the ambient directly
    TWO_NODE = 1  #: wire -> air inside the actuator casing -> open air (Sec. 3.2)


class IntegralReset(Option):
    """When the PID's error integral restarts (Eq. 12a)."""

    SEGMENT = 0  #: at each new target and when an actuator is newly enabled
    NEVER = 1  #: integrate from t = 0 (authors' 2020 model)


class AntiWindup(Option):
    """Integral anti-windup of the PID (Eq. 12a)."""

    NONE = 0  #: plain PID, as in the paper
    CLAMP = 1  #: conditional integration: frozen while the duty is saturated the same way


class JouleHeating(Option):
    """How the electrical drive heats a wire (Eq. 11)."""

    PER_METRE = 0  #: Eq. (11) read literally: V^2 / R_w per metre of wire (the paper's sets)
    WHOLE_WIRE = 1  #: physical: V^2 / (R_w L_w) over the whole wire, i.e. V^2 / (R_w L_w^2) per metre


def _choice(option: type[Option], doc: str) -> Any:
    return field(metadata={"kind": "choice", "choices": tuple(option.labels()), "doc": doc})


@dataclass(frozen=True)
class ModelOptions:
    """Every model option of a run. No defaults: each named set states its own."""

    spring_init: SpringInit = _choice(SpringInit, "initial spring elongations (joint)")
    stress_law: StressLaw = _choice(StressLaw, "constitutive law, Eqs. (7)-(8)")
    friction_sticking: FrictionSticking = _choice(FrictionSticking, "when the mechanism sticks, Eq. (2)")
    damping_switch: DampingSwitch = _choice(DampingSwitch, "which viscous coefficient applies")
    integral_reset: IntegralReset = _choice(IntegralReset, "when the PID error integral restarts")
    anti_windup: AntiWindup = _choice(AntiWindup, "PID integral anti-windup")
    controller_in_cooling: bool = field(metadata={
        "kind": "bool", "doc": "keep the PID on in an actuator's cooling phase (False: 0 V, Fig. 11)"})
    joule_heating: JouleHeating = _choice(JouleHeating, "how the drive heats a wire, Eq. (11)")
    hysteresis: Hysteresis = _choice(Hysteresis, "minor loops of the phase kinetics, Eqs. (9)-(10)")
    thermal_model: ThermalModel = _choice(ThermalModel, "heat transfer of a wire, Eq. (11)")

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name not in OPTION_TYPES:
                if not isinstance(v, bool):
                    raise OptionError(f"{f.name}: {v!r} is not a boolean (true/false)")
                continue
            object.__setattr__(self, f.name, OPTION_TYPES[f.name].parse(f.name, v))

    def replace(self, **changes: Any) -> "ModelOptions":
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Labels (kebab-case strings) and booleans, as in a TOML file."""
        return {f.name: (v if isinstance(v := getattr(self, f.name), bool) else v.label)
                for f in fields(self)}

    def compiled(self) -> "CompiledOptions":
        """The record the compiled code reads (enum members, by name)."""
        return CompiledOptions(**{f.name: getattr(self, f.name) for f in fields(self)})


#: option name -> its enum (booleans are not listed)
OPTION_TYPES: dict[str, type[Option]] = {
    "spring_init": SpringInit,
    "stress_law": StressLaw,
    "friction_sticking": FrictionSticking,
    "damping_switch": DampingSwitch,
    "integral_reset": IntegralReset,
    "anti_windup": AntiWindup,
    "joule_heating": JouleHeating,
    "hysteresis": Hysteresis,
    "thermal_model": ThermalModel,
}
OPTION_NAMES = tuple(f.name for f in fields(ModelOptions))

#: :class:`ModelOptions` as the compiled code receives them: a NamedTuple, same names
CompiledOptions = NamedTuple("CompiledOptions", [(n, OPTION_TYPES.get(n, bool)) for n in OPTION_NAMES])
CompiledOptions.__module__ = __name__


def parse_option(name: str, raw: Any) -> Any:
    """An option value from text (``--set NAME=VALUE``) or a TOML value."""
    if name == "controller_in_cooling":
        if isinstance(raw, bool):
            return raw
        low = str(raw).strip().lower()
        if low in ("1", "true", "yes", "on"):
            return True
        if low in ("0", "false", "no", "off"):
            return False
        raise OptionError(f"{name}: {raw!r} is not a boolean (true/false)")
    return OPTION_TYPES[name].parse(name, raw.strip('"').strip("'") if isinstance(raw, str) else raw)
