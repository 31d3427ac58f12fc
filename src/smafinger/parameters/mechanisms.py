"""The mechanisms SMA wires can drive, and the parameters each one adds.

- :class:`JointParameters`: the paper's MCP finger joint, moved by two opposing wires (upper =
  extensor, lower = flexor), each in series with a spring-slack tendon (Eqs. 1-6).
- :class:`LinearActuatorParameters`: the most common bench rig: one wire pulling a slider
  against a bias spring, with optional end stops.

Each mechanism names its generalized coordinate (:class:`Coordinate`) and its wires; targets,
outputs and gains use them (``theta_deg`` and ``K_P_per_rad`` for the joint, ``position_m``
and ``K_P_per_m`` for the slider).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

from .base import ParameterError, ParameterSet, _num
from .options import SpringInit


class Coordinate(NamedTuple):
    """A mechanism's generalized coordinate q, as users see it."""

    name: str  #: exported as ``{name}_{unit}`` (theta_deg, position_m)
    unit: str  #: user unit of q (deg, m)
    scale: float  #: user value = scale * SI value
    velocity: str  #: exported name of dq/dt (omega_deg_s, velocity_m_s)
    limit: float  #: |target| allowed, in the user unit
    #: issue 11's accuracy budget for q against a converged run, RMS and largest difference, in the
    #: user unit (the settings were validated against it: docs/speed.md; :mod:`smafinger.step_check`)
    accuracy_rms: float
    accuracy_max: float


@dataclass(frozen=True, kw_only=True)
class JointParameters(ParameterSet):
    """The finger joint of Gilardi et al. (2010): Eqs. (1)-(6) and MODEL-NOTES' geometry."""

    mechanism: ClassVar[str] = "joint"
    wire_names: ClassVar[tuple[str, ...]] = ("upper", "lower")
    coordinate: ClassVar[Coordinate] = Coordinate("theta", "deg", 180.0 / math.pi, "omega_deg_s", 89.0, 0.05, 0.3)

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
    spring_length_upper_m: float = _num(0.0, 1.0, "initial upper spring length (used with spring_init = "
                                        "given; equilibrium solves it from theta0_deg)")
    spring_length_lower_m: float = _num(0.0, 1.0, "initial lower spring length")
    slack_m: float = _num(0.0, 1.0, "spring elongation beyond initial at which slack is taken up")
    slack_band_m: float = _num(0.0, 1.0, "stiffening starts this far before the slack point")
    slack_penalty_per_mm: float = _num(0.0, 100.0, "cosh penalty factor (1/mm)")

    # --- controller gains (Eq. 12a), DC% per radian of error ------------------------------
    K_P_per_rad: float = _num(0.0, 1e7, "proportional gain K_P (% per rad)")
    K_V_s_per_rad: float = _num(0.0, 1e7, "derivative gain K_V (% s per rad)")
    K_I_per_rad_s: float = _num(0.0, 1e7, "integral gain K_I (% per rad s)")

    def to_si(self, value: float) -> float:
        """A target or tolerance in degrees, in radians."""
        return math.radians(value)

    @property
    def initial_target(self) -> float:
        """The coordinate at the start, in the user unit (deg)."""
        return self.theta0_deg

    def replace(self, **changes):
        """A copy with some parameters or options changed (validated); a new
        ``spring_length_upper_m`` is refused where ``spring_init = equilibrium`` ignores it.

        Set back to equilibrium alone (a given start's own length left as it was), the length
        it now ignores takes the value of the named set whose name the copy keeps: the set is
        the one its file reads back as (a file's edit of it is refused), and a sweep over
        ``spring_init`` runs (found by review)."""
        new = super().replace(**changes)
        if "spring_length_upper_m" not in changes and "spring_init" not in changes:
            return new
        from . import REGISTRY, get

        named = get(new.name) if ("name" not in changes and new.name in REGISTRY) else None
        reference = named if type(named) is type(new) else self
        if "spring_length_upper_m" not in changes and new.spring_init == SpringInit.EQUILIBRIUM:
            return super(JointParameters, new).replace(spring_length_upper_m=reference.spring_length_upper_m)
        new.refuse_ignored_changes(reference)
        return new

    def refuse_ignored_changes(self, before: "JointParameters") -> None:
        """:class:`ParameterError` if this set differs from ``before`` in a value its options
        ignore: ``spring_length_upper_m`` under ``spring_init = equilibrium`` (a change there would
        run unchanged while the summary names it changed)."""
        if (self.spring_init == SpringInit.EQUILIBRIUM
                and self.spring_length_upper_m != before.spring_length_upper_m):
            raise ParameterError(
                f"spring_length_upper_m = {self.spring_length_upper_m} has no effect with spring_init = "
                f"equilibrium (the upper spring is solved from the moment balance at theta0_deg; "
                f"{before.name} has {before.spring_length_upper_m}); set spring_init=given with it")

    def _cross_checks(self) -> None:
        super()._cross_checks()
        for side in self.wire_names:
            length = getattr(self, f"spring_length_{side}_m")
            if not length > self.spring_free_length_m:
                raise ParameterError(
                    f"spring_length_{side}_m = {length} must exceed spring_free_length_m = "
                    f"{self.spring_free_length_m} (the bias spring starts stretched)")
        if self.slack_band_m > self.slack_m:
            raise ParameterError(f"slack_band_m = {self.slack_band_m} must not exceed slack_m = {self.slack_m}")


@dataclass(frozen=True, kw_only=True)
class LinearActuatorParameters(ParameterSet):
    """One wire pulling a slider against a bias spring (the usual bench rig).

    The coordinate x is the slider's displacement from its start, positive in the direction
    the wire pulls (contraction). At x the bias spring pulls back with
    ``bias_spring_preload_N + bias_spring_K_N_m * x`` and a constant ``external_force_N``
    (a hanging load, say) adds to it; the wire starts in static equilibrium with both.
    """

    mechanism: ClassVar[str] = "linear-bias-spring"
    wire_names: ClassVar[tuple[str, ...]] = ("wire",)
    coordinate: ClassVar[Coordinate] = Coordinate("position", "m", 1.0, "velocity_m_s", 1.0, 0.05e-3, 0.6e-3)

    slider_mass_kg: float = _num(1e-6, 100.0, "mass of the slider (and what moves with it)")
    viscous_damping_N_s_m: float = _num(0.0, 1e5, "viscous friction coefficient of the slider")
    static_friction_N: float = _num(0.0, 1e4, "static friction force (0: never sticks)")
    coulomb_friction_N: float = _num(0.0, 1e4, "dynamic (Coulomb) friction force")
    stick_velocity_m_s: float = _num(0.0, 1.0, "below this speed the slider may stick")
    bias_spring_K_N_m: float = _num(0.0, 1e7, "bias spring stiffness")
    bias_spring_preload_N: float = _num(0.0, 1e4, "bias spring force at the start position (x = 0)")
    external_force_N: float = _num(-1e4, 1e4, "constant load opposing the wire (e.g. m g of a hanging mass)")
    stroke_min_m: float = _num(-10.0, 0.0, "end stop below the start position (-inf-like: -10 m)")
    stroke_max_m: float = _num(0.0, 10.0, "end stop above the start position")

    # --- controller gains (Eq. 12a), DC% per metre of error -------------------------------
    K_P_per_m: float = _num(0.0, 1e9, "proportional gain (% per m)")
    K_V_s_per_m: float = _num(0.0, 1e9, "derivative gain (% s per m)")
    K_I_per_m_s: float = _num(0.0, 1e9, "integral gain (% per m s)")

    def to_si(self, value: float) -> float:
        """A target or tolerance in metres (already SI)."""
        return float(value)

    @property
    def initial_target(self) -> float:
        """The coordinate at the start, in the user unit (m): the slider starts at 0."""
        return 0.0

    def _cross_checks(self) -> None:
        super()._cross_checks()
        if not self.bias_spring_preload_N + self.external_force_N > 0.0:
            raise ParameterError(
                f"bias_spring_preload_N + external_force_N = {self.bias_spring_preload_N + self.external_force_N} N: "
                "the wire must start taut (a positive load at the start position)")


#: mechanism label -> its parameter class
MECHANISMS: dict[str, type[ParameterSet]] = {
    JointParameters.mechanism: JointParameters,
    LinearActuatorParameters.mechanism: LinearActuatorParameters,
}
