"""Typed, validated, immutable parameter sets.

A :class:`ParameterSet` holds every number the model needs, in SI units with the unit in
the field name (degrees only in fields ending ``_deg``, at the user's edge). Each field
declares its allowed range; constructing a set with a value outside it raises
:class:`ParameterError` naming the field, the value and the range.

Derived quantities (wire cross-section, mass per length, initial spring elongations from
static equilibrium, ...) are never stored: they are computed from the set when needed.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any


class ParameterError(ValueError):
    """A parameter value is missing, of the wrong type, or outside its allowed range."""


def _num(lo: float, hi: float, doc: str) -> Any:
    return field(metadata={"kind": "float", "range": (lo, hi), "doc": doc})


def _choice(choices: tuple[str, ...], doc: str) -> Any:
    return field(metadata={"kind": "choice", "choices": choices, "doc": doc})


def _flag(doc: str) -> Any:
    return field(metadata={"kind": "bool", "doc": doc})


@dataclass(frozen=True)
class ParameterSet:
    """All parameters of the finger-joint model (SI units, unit in each name).

    No field has a default: the named sets in :mod:`smafinger.parameters.paper2010` and
    :mod:`smafinger.parameters.authors2020` give every value explicitly, with its source.
    """

    name: str = field(metadata={"kind": "str", "doc": "name of the set"})
    source: str = field(metadata={"kind": "str", "doc": "citation of the values"})

    # --- SMA wire (Table II) -------------------------------------------------------------
    wire_density_kg_m3: float = _num(1e3, 2e4, "wire density rho_w")
    wire_diameter_m: float = _num(1e-5, 5e-3, "wire diameter d_w")
    wire_length_m: float = _num(1e-3, 10.0, "unstretched wire length L_w")
    specific_heat_J_kgK: float = _num(10.0, 5e3, "specific heat C_p")
    resistance_ohm_per_m: float = _num(1e-3, 1e4, "electrical resistance per length R_w")
    A_S0_C: float = _num(-100.0, 300.0, "austenite start temperature at zero stress")
    A_F0_C: float = _num(-100.0, 300.0, "austenite finish temperature at zero stress")
    M_S0_C: float = _num(-100.0, 300.0, "martensite start temperature at zero stress")
    M_F0_C: float = _num(-100.0, 300.0, "martensite finish temperature at zero stress")
    c_A_Pa_per_C: float = _num(1e4, 1e10, "austenite stress-temperature slope c_A")
    c_M_Pa_per_C: float = _num(1e4, 1e10, "martensite stress-temperature slope c_M")
    D_A_Pa: float = _num(1e8, 1e12, "austenite Young's modulus D_A")
    D_M_Pa: float = _num(1e8, 1e12, "martensite Young's modulus D_M")
    eps_R: float = _num(1e-6, 0.2, "maximum recoverable strain eps_R")
    xi_init: float = _num(0.0, 1.0, "initial martensite fraction of both wires")
    minor_loop_reversal_C: float = _num(
        0.0, 50.0,
        "temperature reversal needed to switch kinetics branch (0: sign of dT/dt, authors' model; "
        ">0 keeps PWM ripple from ratcheting xi through minor loops)",
    )

    # --- heat transfer (Eq. 11) -----------------------------------------------------------
    T_amb_C: float = _num(-50.0, 200.0, "ambient temperature")
    T_init_C: float = _num(-50.0, 300.0, "initial wire temperature")
    h0_heating_W_m2K: float = _num(0.0, 1e4, "h0 while the actuator is heating")
    h2_heating_W_m2K3: float = _num(0.0, 1.0, "h2 while the actuator is heating")
    h0_cooling_W_m2K: float = _num(0.0, 1e4, "h0 while the actuator is cooling or off")
    h2_cooling_W_m2K3: float = _num(0.0, 1.0, "h2 while the actuator is cooling or off")

    # --- joint (Eqs. 1-2) -----------------------------------------------------------------
    inertia_kg_m2: float = _num(1e-9, 1.0, "phalanx moment of inertia I")
    mass_kg: float = _num(0.0, 10.0, "phalanx mass m")
    d_CM_m: float = _num(0.0, 1.0, "joint-to-centre-of-mass distance d_CM")
    gravity_m_s2: float = _num(0.0, 100.0, "gravitational acceleration g")
    M_SF_Nm: float = _num(0.0, 10.0, "static friction moment M_SF")
    M_DF_Nm: float = _num(0.0, 10.0, "dynamic (Coulomb) friction moment M_DF")
    C_DF_heating_Nms: float = _num(0.0, 10.0, "viscous friction coefficient, heating")
    C_DF_cooling_Nms: float = _num(0.0, 10.0, "viscous friction coefficient, cooling")
    stick_velocity_rad_s: float = _num(0.0, 10.0, "below this speed the joint may stick")
    theta0_deg: float = _num(-89.0, 89.0, "initial joint angle")

    # --- geometry (MODEL-NOTES, authors' model) --------------------------------------------
    a1_m: float = _num(1e-4, 0.2, "geometry a1 (height of C and D)")
    a2_m: float = _num(1e-4, 0.2, "geometry a2 (X of D)")
    a3_m: float = _num(1e-4, 0.2, "geometry a3 (X of B at theta = 0)")
    a4_m: float = _num(1e-4, 0.2, "geometry a4 (-X of lower C)")
    a5_m: float = _num(0.0, 0.2, "geometry a5 (-X of upper C)")

    # --- spring-slack tendons --------------------------------------------------------------
    spring_K_N_m: float = _num(1e-3, 1e6, "bias spring stiffness K_S")
    spring_free_length_m: float = _num(0.0, 1.0, "spring unstretched length")
    spring_length_upper_m: float = _num(0.0, 1.0, "initial upper spring length")
    spring_length_lower_m: float = _num(0.0, 1.0, "initial lower spring length")
    spring_init: str = _choice(
        ("given", "equilibrium"),
        "'given': both initial spring lengths as set; 'equilibrium': lower as set, upper "
        "solved from the friction-free moment balance at theta0",
    )
    slack_m: float = _num(0.0, 1.0, "spring elongation beyond initial at which slack is taken up")
    slack_band_m: float = _num(0.0, 1.0, "stiffening starts this far before the slack point")
    slack_penalty_per_mm: float = _num(0.0, 100.0, "cosh penalty factor (1/mm)")

    # --- drive and controller (Eq. 12, Sec. 2.6) -------------------------------------------
    V_H_V: float = _num(0.0, 100.0, "PWM high voltage V_H")
    V_L_V: float = _num(0.0, 100.0, "PWM low voltage V_L")
    pwm_period_s: float = _num(1e-6, 1.0, "PWM period t_P")
    K_P_per_rad: float = _num(0.0, 1e7, "proportional gain K_P (% per rad)")
    K_V_s_per_rad: float = _num(0.0, 1e7, "derivative gain K_V (% s per rad)")
    K_I_per_rad_s: float = _num(0.0, 1e7, "integral gain K_I (% per rad s)")
    controller_update_s: float = _num(0.0, 10.0, "controller update interval (0: every step)")
    controller_in_cooling: bool = _flag(
        "keep the PID on in an actuator's cooling phase (False: 0 V while cooling, Fig. 11)"
    )
    integral_reset: str = _choice(
        ("segment", "never"),
        "'segment': reset the error integral at each new target and when an actuator is "
        "newly enabled; 'never': integrate from t = 0 (authors' 2020 model)",
    )
    anti_windup: str = _choice(
        ("none", "clamp"),
        "'clamp': stop integrating while the duty is saturated and the error would push it "
        "further (conditional integration); 'none': plain PID as in the paper",
    )

    # --- model options ---------------------------------------------------------------------
    stress_law: str = _choice(
        ("rate", "algebraic"),
        "'rate': integrate Eq. (7b); 'algebraic': sigma = D_eq (eps - eps_R xi) solved with xi "
        "(authors' 2020 model)",
    )
    friction_sticking: str = _choice(
        ("restick", "initial-only"),
        "'restick': the joint sticks whenever it comes to rest with |M_E| <= M_SF; "
        "'initial-only': held only while its velocity is exactly zero (authors' 2020 model)",
    )
    damping_switch: str = _choice(
        ("heating-phase", "enabled"),
        "C_DF heating while any actuator is in its heating phase ('heating-phase') or while any "
        "actuator is enabled ('enabled', authors' 2020 model); C_DF cooling otherwise",
    )

    def __post_init__(self) -> None:
        for f in fields(self):
            _check_field(f, getattr(self, f.name))
        _cross_checks(self)

    # ----------------------------------------------------------------------------------
    def replace(self, **changes: Any) -> "ParameterSet":
        """A copy with some fields changed (validated)."""
        unknown = set(changes) - {f.name for f in fields(self)}
        if unknown:
            raise ParameterError(f"unknown parameter(s): {', '.join(sorted(unknown))}")
        return dataclasses.replace(self, **changes)

    def with_overrides(self, assignments: list[str] | tuple[str, ...]) -> "ParameterSet":
        """Apply ``NAME=VALUE`` strings (as given with ``--set``)."""
        changes: dict[str, Any] = {}
        for a in assignments:
            if "=" not in a:
                raise ParameterError(f"override {a!r} is not of the form NAME=VALUE")
            key, raw = (s.strip() for s in a.split("=", 1))
            changes[key] = parse_value(key, raw)
        return self.replace(**changes)

    def to_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def to_toml(self) -> str:
        lines = ["# smafinger parameter set (SI units; unit in each name)"]
        for f in fields(self):
            v = getattr(self, f.name)
            doc = f.metadata.get("doc", "")
            lines.append(f"{f.name} = {_toml_value(v)}  # {doc}" if doc else f"{f.name} = {_toml_value(v)}")
        return "\n".join(lines) + "\n"

    def save(self, path: str | Path) -> None:
        """Write the set as TOML (written to a temporary file first: never half-written)."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(self.to_toml())
        tmp.replace(path)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(v))


def field_spec(name: str) -> dataclasses.Field:
    for f in fields(ParameterSet):
        if f.name == name:
            return f
    raise ParameterError(f"unknown parameter: {name!r}")


def parse_value(name: str, raw: str) -> Any:
    """Parse a ``--set`` value according to the field's kind."""
    f = field_spec(name)
    kind = f.metadata["kind"]
    if kind == "float":
        try:
            return float(raw)
        except ValueError:
            raise ParameterError(f"{name}: {raw!r} is not a number") from None
    if kind == "bool":
        low = raw.lower()
        if low in ("1", "true", "yes", "on"):
            return True
        if low in ("0", "false", "no", "off"):
            return False
        raise ParameterError(f"{name}: {raw!r} is not a boolean (true/false)")
    return raw.strip('"').strip("'")


def _check_field(f: dataclasses.Field, v: Any) -> None:
    kind = f.metadata["kind"]
    if kind == "float":
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ParameterError(f"{f.name}: {v!r} is not a number")
        lo, hi = f.metadata["range"]
        if not math.isfinite(v) or not (lo <= v <= hi):
            raise ParameterError(f"{f.name} = {v!r} is outside the allowed range [{lo:g}, {hi:g}]")
    elif kind == "choice":
        if v not in f.metadata["choices"]:
            raise ParameterError(f"{f.name} = {v!r} is not one of {', '.join(f.metadata['choices'])}")
    elif kind == "bool":
        if not isinstance(v, bool):
            raise ParameterError(f"{f.name}: {v!r} is not a boolean")
    elif kind == "str":
        if not isinstance(v, str):
            raise ParameterError(f"{f.name}: {v!r} is not a string")


def _cross_checks(p: ParameterSet) -> None:
    def bad(msg: str) -> None:
        raise ParameterError(msg)

    if not p.A_S0_C < p.A_F0_C:
        bad(f"A_S0_C = {p.A_S0_C} must be below A_F0_C = {p.A_F0_C}")
    if not p.M_F0_C < p.M_S0_C:
        bad(f"M_F0_C = {p.M_F0_C} must be below M_S0_C = {p.M_S0_C}")
    if p.V_L_V > p.V_H_V:
        bad(f"V_L_V = {p.V_L_V} must not exceed V_H_V = {p.V_H_V}")
    for side in ("upper", "lower"):
        length = getattr(p, f"spring_length_{side}_m")
        if not length > p.spring_free_length_m:
            bad(
                f"spring_length_{side}_m = {length} must exceed spring_free_length_m = "
                f"{p.spring_free_length_m} (the bias spring starts stretched)"
            )
    if p.slack_band_m > p.slack_m:
        bad(f"slack_band_m = {p.slack_band_m} must not exceed slack_m = {p.slack_m}")
    if p.T_init_C < p.T_amb_C - 100.0:
        bad(f"T_init_C = {p.T_init_C} is implausibly far below T_amb_C = {p.T_amb_C}")


def load_toml(path: str | Path, registry_get) -> ParameterSet:
    """Load a parameter file. ``base = "NAME"`` starts from a named set; other keys override."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ParameterError(f"parameter file not found: {path}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None
    base_name = data.pop("base", None)
    names = {f.name for f in fields(ParameterSet)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ParameterError(f"{path}: unknown parameter(s): {', '.join(unknown)}")
    if base_name is not None:
        return registry_get(base_name).replace(**data)
    missing = sorted(names - set(data) - {"name", "source"})
    if missing:
        raise ParameterError(
            f"{path}: missing parameter(s) {', '.join(missing)} (or give base = \"paper2010\")"
        )
    try:
        return ParameterSet(**data)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None
