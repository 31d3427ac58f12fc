"""Typed, validated, immutable parameter sets.

A :class:`ParameterSet` holds every number one SMA wire actuator needs, in SI units with the
unit in the field name (degrees only in fields ending ``_deg``, at the user's edge), plus its
:class:`~smafinger.parameters.options.ModelOptions`. Each field declares its allowed range;
constructing a set with a value outside it raises :class:`ParameterError` naming the field,
the value and the range.

The base class declares what every wire actuator has (the SMA wire, its heat transfer, its
drive); :mod:`smafinger.parameters.mechanisms` adds what each mechanism has (the paper's finger
joint, the linear bias-spring actuator). Fields marked ``wire=True`` reach the compiled code
by the same name, one row per wire (:mod:`smafinger.model.records`).

Derived quantities (wire cross-section, mass per length, initial spring elongations, ...) are
never stored: they are computed from the set when the run is built.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from ..values import is_real, one_or_many
from .errors import ParameterError
from .options import OPTION_NAMES, OPTION_TYPES, ModelOptions, parse_option


def _num(lo: float, hi: float, doc: str, wire: bool = False, **kw: Any) -> Any:
    """A float field in [lo, hi]; ``wire``: copied by name into each wire's compiled record."""
    return field(metadata={"kind": "float", "range": (lo, hi), "doc": doc, "wire": wire}, **kw)


def _text(doc: str) -> Any:
    return field(metadata={"kind": "str", "doc": doc})


@dataclass(frozen=True, kw_only=True)
class ParameterSet:
    """What every SMA wire actuator has: the wire, its heat transfer, its drive and controller.

    Use a mechanism's set (:class:`~smafinger.parameters.mechanisms.JointParameters`,
    :class:`~smafinger.parameters.mechanisms.LinearActuatorParameters`); the named sets in
    :mod:`smafinger.parameters` give every value explicitly, with its source.
    """

    #: mechanism label (``mechanism = "..."`` in a parameter file)
    mechanism: ClassVar[str] = ""

    name: str = _text("name of the set")
    source: str = _text("citation of the values")

    # --- SMA wire (Table II) -------------------------------------------------------------
    wire_density_kg_m3: float = _num(1e3, 2e4, "wire density rho_w")
    wire_diameter_m: float = _num(1e-5, 5e-3, "wire diameter d_w")
    wire_length_m: float = _num(1e-3, 10.0, "unstretched wire length L_w", wire=True)
    specific_heat_J_kgK: float = _num(10.0, 5e3, "specific heat C_p", wire=True)
    resistance_ohm_per_m: float = _num(1e-3, 1e4, "electrical resistance per length R_w", wire=True)
    A_S0_C: float = _num(-100.0, 300.0, "austenite start temperature at zero stress", wire=True)
    A_F0_C: float = _num(-100.0, 300.0, "austenite finish temperature at zero stress", wire=True)
    M_S0_C: float = _num(-100.0, 300.0, "martensite start temperature at zero stress", wire=True)
    M_F0_C: float = _num(-100.0, 300.0, "martensite finish temperature at zero stress", wire=True)
    c_A_Pa_per_C: float = _num(1e4, 1e10, "austenite stress-temperature slope c_A", wire=True)
    c_M_Pa_per_C: float = _num(1e4, 1e10, "martensite stress-temperature slope c_M", wire=True)
    D_A_Pa: float = _num(1e8, 1e12, "austenite Young's modulus D_A", wire=True)
    D_M_Pa: float = _num(1e8, 1e12, "martensite Young's modulus D_M", wire=True)
    eps_R: float = _num(1e-6, 0.2, "maximum recoverable strain eps_R", wire=True)
    xi_init: float = _num(0.0, 1.0, "initial martensite fraction of every wire", wire=True)
    minor_loop_reversal_C: float = _num(
        0.0, 50.0,
        "dead band of the 'deadband' hysteresis rule (smafinger 0.1): the temperature reversal that "
        "switches the kinetics branch", wire=True,
    )

    # --- heat transfer (Eq. 11) -----------------------------------------------------------
    T_amb_C: float = _num(-50.0, 200.0, "ambient temperature", wire=True)
    T_init_C: float = _num(-50.0, 300.0, "initial wire temperature", wire=True)
    h0_heating_W_m2K: float = _num(0.0, 1e4, "h0 while the actuator is heating", wire=True)
    h2_heating_W_m2K3: float = _num(0.0, 1.0, "h2 while the actuator is heating", wire=True)
    h0_cooling_W_m2K: float = _num(0.0, 1e4, "h0 while the actuator is cooling or off", wire=True)
    h2_cooling_W_m2K3: float = _num(0.0, 1.0, "h2 while the actuator is cooling or off", wire=True)
    latent_heat_J_kg: float = _num(
        0.0, 1e6, "latent heat of the transformation (0: off, as in the paper; NiTi: about 24e3)",
        wire=True, default=0.0)
    # two-node model (thermal_model = "two-node"): wire -> casing air -> open air, per metre of wire
    casing_heat_capacity_J_mK: float = _num(
        1e-6, 1e6, "heat capacity of the actuator casing and its air, per metre of wire (two-node model)",
        wire=True, default=20.0)
    casing_loss_W_mK: float = _num(
        0.0, 1e4, "heat loss of the casing to the open air per kelvin, per metre of wire (two-node model)",
        wire=True, default=0.08)
    emissivity: float = _num(
        0.0, 1.0, "emissivity of the wire's surface for radiative loss (0: off, as in the paper; "
        "polished NiTi: about 0.1-0.3)", wire=True, default=0.0)

    # --- electrical resistance as sensed (model.resistance, Eqs. R1-R2; not Eq. 11's R_w) ---
    # defaults: the MAS model's values for actuator NiTi wire (docs/controllers.md, "Self-sensing")
    resistivity_austenite_ohm_m: float = _num(
        1e-8, 1e-4, "resistivity of austenite at resistivity_reference_C", wire=True, default=8.9e-7)
    resistivity_martensite_ohm_m: float = _num(
        1e-8, 1e-4, "resistivity of (detwinned) martensite at resistivity_reference_C", wire=True, default=1.02e-6)
    resistivity_tc_austenite_per_K: float = _num(
        -1e-2, 1e-2, "temperature coefficient of the austenite resistivity", wire=True, default=2e-4)
    resistivity_tc_martensite_per_K: float = _num(
        -1e-2, 1e-2, "temperature coefficient of the martensite resistivity", wire=True, default=3e-4)
    resistivity_reference_C: float = _num(
        -100.0, 300.0, "temperature at which the two resistivities are given", wire=True, default=20.0)

    # --- drive and controller (Eq. 12, Sec. 2.6) -------------------------------------------
    V_H_V: float = _num(0.0, 100.0, "PWM high voltage V_H (the supply)")
    V_L_V: float = _num(0.0, 100.0, "PWM low voltage V_L")
    pwm_period_s: float = _num(1e-6, 1.0, "PWM period t_P")
    controller_update_s: float = _num(0.0, 10.0, "controller update interval (0: every step)")

    options: ModelOptions = field(metadata={"kind": "options", "doc": "model options"})

    def __post_init__(self) -> None:
        if not isinstance(self.options, ModelOptions):
            raise ParameterError(f"options: {self.options!r} is not a ModelOptions")
        for f in fields(self):
            if f.name != "options":
                value = _checked_field(f, getattr(self, f.name))
                if value is not getattr(self, f.name):
                    # a whole number (V_H_V = 6 in a file) or a numpy scalar: stored as float, as the
                    # compiled records expect
                    object.__setattr__(self, f.name, value)
        self._cross_checks()

    def __getattr__(self, name: str) -> Any:
        # a model option read like a parameter: p.stress_law is p.options.stress_law
        if name in OPTION_NAMES:
            return getattr(self.options, name)
        raise AttributeError(f"{type(self).__name__} has no parameter or option {name!r}")

    # ----------------------------------------------------------------------------------
    def _cross_checks(self) -> None:
        """Relations between fields (a subclass adds its own)."""
        if not self.A_S0_C < self.A_F0_C:
            raise ParameterError(f"A_S0_C = {self.A_S0_C} must be below A_F0_C = {self.A_F0_C}")
        if not self.M_F0_C < self.M_S0_C:
            raise ParameterError(f"M_F0_C = {self.M_F0_C} must be below M_S0_C = {self.M_S0_C}")
        from ..model.hysteresis import material_from_parameters

        try:  # the kinetics' own rule: a major loop that is not empty at zero stress
            material_from_parameters(self)
        except ValueError as exc:
            raise ParameterError(f"{exc} (the major hysteresis loop would be empty)") from None
        if self.V_L_V > self.V_H_V:
            raise ParameterError(f"V_L_V = {self.V_L_V} must not exceed V_H_V = {self.V_H_V}")
        if self.T_init_C < self.T_amb_C - 100.0:
            raise ParameterError(f"T_init_C = {self.T_init_C} is implausibly far below T_amb_C = {self.T_amb_C}")

    @classmethod
    def field_names(cls) -> list[str]:
        return [f.name for f in fields(cls) if f.name != "options"]

    def replace(self, **changes: Any) -> "ParameterSet":
        """A copy with some parameters or options changed (validated)."""
        names = set(self.field_names())
        unknown = set(changes) - names - set(OPTION_NAMES) - {"options"}
        if unknown:
            raise ParameterError(f"unknown parameter(s) for a {self.mechanism} set: {', '.join(sorted(unknown))}")
        opt = {k: changes.pop(k) for k in list(changes) if k in OPTION_NAMES}
        if opt:
            changes["options"] = changes.get("options", self.options).replace(**opt)
        return dataclasses.replace(self, **changes)

    def with_overrides(self, assignments: list[str] | tuple[str, ...]) -> "ParameterSet":
        """Apply ``NAME=VALUE`` strings (as given with ``--set``)."""
        changes: dict[str, Any] = {}
        for a in one_or_many(assignments):
            if "=" not in a:
                raise ParameterError(f"override {a!r} is not of the form NAME=VALUE")
            key, raw = (s.strip() for s in a.split("=", 1))
            changes[key] = parse_value(key, raw, type(self))
        return self.replace(**changes)

    def to_dict(self) -> dict[str, Any]:
        """Every parameter and option by name (options as their kebab-case labels)."""
        d = {n: getattr(self, n) for n in self.field_names()}
        d.update(self.options.to_dict())
        return d

    def to_toml(self) -> str:
        from .files import to_toml

        return to_toml(self)

    def save(self, path) -> None:
        """Write the set as TOML (via a temporary file: never half-written)."""
        from ..files import atomic_write_text

        atomic_write_text(path, self.to_toml())


def field_spec(name: str, cls: type | None = None) -> dataclasses.Field:
    """The declaration of a parameter or option (searched in every mechanism if ``cls`` is None)."""
    from .mechanisms import MECHANISMS

    for c in ([cls] if cls is not None else list(MECHANISMS.values())):
        for f in fields(c):
            if f.name == name and f.name != "options":
                return f
    for f in fields(ModelOptions):
        if f.name == name:
            return f
    raise ParameterError(f"unknown parameter: {name!r}")


def field_kind(f: dataclasses.Field) -> str:
    """``float``, ``str``, ``choice`` (an option) or ``bool`` (an option)."""
    if f.name in OPTION_TYPES:
        return "choice"
    if f.name in OPTION_NAMES:
        return "bool"
    return f.metadata["kind"]


def parse_value(name: str, raw: str, cls: type | None = None) -> Any:
    """Parse a ``--set`` value according to the field's kind (``cls``: the set's class)."""
    if name in OPTION_NAMES:
        return parse_option(name, raw)
    f = field_spec(name, cls)
    if f.metadata["kind"] == "float":
        try:
            return float(raw)
        except ValueError:
            raise ParameterError(f"{name}: {raw!r} is not a number") from None
    return raw.strip('"').strip("'")


def checked_real(name: str, v: Any, lo: float, hi: float, prefix: str = "") -> float:
    """``v`` as a float within [lo, hi] (:func:`smafinger.values.is_real`); :class:`ParameterError`
    naming ``prefix`` + ``name`` and the value otherwise (an int beyond any float is out of range)."""
    if not is_real(v):
        raise ParameterError(f"{prefix}{name}: {v!r} is not a number")
    try:
        x = float(v)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x) or not (lo <= x <= hi):
        raise ParameterError(f"{prefix}{name} = {v!r:.40} is outside the allowed range [{lo:g}, {hi:g}]")
    return x


def _checked_field(f: dataclasses.Field, v: Any) -> Any:
    """``v`` checked against the field's kind and range: a number as a Python float (an int, a
    numpy scalar), other kinds as given; :class:`ParameterError` naming the field and the value."""
    kind = f.metadata["kind"]
    if kind == "float":
        lo, hi = f.metadata["range"]
        x = checked_real(f.name, v, lo, hi)
        return v if type(v) is float else x
    if kind == "str":
        if not isinstance(v, str):
            raise ParameterError(f"{f.name}: {v!r} is not a string")
        try:
            v.encode("utf-8")
        except UnicodeEncodeError:  # a byte of another encoding on the command line (a surrogate)
            raise ParameterError(f"{f.name}: {v!r} is not valid text (UTF-8)") from None
    return v
