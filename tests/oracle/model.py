"""The oracle's model: built from a parameter set's fields, and its right-hand side.

:func:`build` reads a :class:`~smafinger.parameters.ParameterSet` (fields and named options
only; every derived quantity is computed here) into an :class:`OracleModel`;
:func:`derivative` gives the state's rates at a :class:`Vars` state with the :class:`Held`
inputs, every component named, with the algebraic quantities (load, xi, stress, ...) and, for
each value, the sum of the magnitudes of the terms it was computed from (its scale, for
round-off-aware comparisons).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from . import material as mat
from . import mechanics as mech
from .hysteresis import Kinetics, MemoryBranch


@dataclass(frozen=True)
class Wire:
    name: str
    L_w: float
    S_w: float
    M_w: float  #: mass per metre
    A_w: float  #: surface per metre (pi d_w)
    C_p: float
    R_per_m: float
    T_amb: float
    h_heating: tuple[float, float]  #: (h0, h2)
    h_cooling: tuple[float, float]
    transformation: mat.Transformation
    D_A: float
    D_M: float
    eps_R: float
    spring: mat.SpringSlack | None  #: None: the wire pulls directly (rigid)
    sigma0: float  #: stress at the start
    eps0: float  #: total strain (wire + spring, elastic + transformation) at the start
    path0: float  #: path length at the start
    xi_init: float
    T_init: float
    latent_heat: float = 0.0  #: dH [J/kg] (0: off, as in the paper)
    casing_capacity: float = 1.0  #: C_case [J/(m K)], two-node model
    casing_loss: float = 0.0  #: G [W/(m K)], two-node model


@dataclass(frozen=True)
class Joint:
    """The paper's MCP joint (Eqs. 1-6): q = theta."""

    inertia: float
    weight_moment: tuple[float, float, float]  #: (m, g, d_CM)
    static: float
    dynamic: float
    viscous_heating: float
    viscous_cooling: float
    stick_velocity: float
    q0: float
    r: float
    alpha0: tuple[float, float]  #: upper, lower
    C: tuple[tuple[float, float], tuple[float, float]]  #: upper, lower
    D: tuple[tuple[float, float], tuple[float, float]]
    q_min: float = -math.inf
    q_max: float = math.inf

    def up(self, theta: float) -> bool:
        """Configuration switch (MODEL-NOTES): Y of B_U at or above Y of C_U."""
        return attachment(self, 0, theta)[1] >= self.C[0][1]

    def wire_geometry(self, theta: float) -> list[tuple[float, float, float]]:
        """Per wire: (path, d path/d theta, moment about O per unit tension)."""
        up = self.up(theta)
        out = []
        for i, wrapped in ((0, not up), (1, up)):  # the upper wraps while down, the lower while up
            B = attachment(self, i, theta)
            path, P = mech.tendon_path(B, self.C[i], self.D[i], wrapped)
            out.append((path, mech.path_rate(B, P), mech.tendon_moment_arm(B, P)))
        return out

    def external(self, theta: float) -> float:
        return mech.gravity_moment(*self.weight_moment, theta)


def attachment(j: Joint, i: int, theta: float):
    return mech.attachment_point(j.r, j.alpha0[i], theta)


@dataclass(frozen=True)
class Slider:
    """One wire pulling a slider against a bias spring: q = x, the wire's path shortens by x."""

    inertia: float
    spring: tuple[float, float, float]  #: (K, preload, external force)
    static: float
    dynamic: float
    viscous_heating: float
    viscous_cooling: float
    stick_velocity: float
    q_min: float
    q_max: float
    q0: float = 0.0

    def wire_geometry(self, x: float) -> list[tuple[float, float, float]]:
        return [(-x, -1.0, 1.0)]

    def external(self, x: float) -> float:
        return mech.bias_spring_load(*self.spring, x)


@dataclass(frozen=True)
class OracleModel:
    mechanism: Joint | Slider
    wires: tuple[Wire, ...]
    algebraic: bool  #: stress law
    whole_wire: bool  #: Joule heating reading
    two_node: bool  #: thermal model: wire -> casing air -> open air
    restick: bool  #: friction sticking
    damping: str  #: which viscous coefficient: "heating-phase", "enabled" or "heating-value"
    rule: str  #: hysteresis: "memory", "authors2020" or "deadband"
    reversal: float  #: the deadband rule's reversal [degC] (0 for the other rules)
    V_H: float
    V_L: float
    pwm_period: float
    initial_target: float  #: q_F of an open-loop run [SI]


# --------------------------------------------------------------------------------------------
# state and held inputs
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class WireVars:
    T: float
    sigma: float
    electrical: float = 0.0  #: electrical energy at the terminals [J]
    heat: float = 0.0  #: Joule heat put into the wire (Eq. 11's P' times L_w, integrated) [J]
    T_case: float = 0.0  #: casing air [degC] (two-node model; unused by the single-node model)


@dataclass(frozen=True)
class Vars:
    q: float
    v: float
    error_integral: float
    wires: tuple[WireVars, ...]


@dataclass(frozen=True)
class WireHeld:
    drive: float  #: V, or A with a current drive
    heating: bool  #: its controller's heating phase (h of Eq. 11)
    branch: Kinetics | MemoryBranch  #: where xi comes from (Eqs. 9-10)


@dataclass(frozen=True)
class Held:
    stuck: bool
    viscous: float
    q_target: float
    integrating: float
    current: bool
    wires: tuple[WireHeld, ...]


@dataclass
class Derivative:
    """Named rates, named algebraic outputs and (if asked for) the round-off scale of each.

    ``drivers``: per wire name, (dT/dt, dsigma/dt) of the wire's state (with the algebraic law,
    the rate of the solved stress): what moves its kinetics (the memory rule's
    tau = T - sigma/c, or T for the legacy rules).
    """

    rates: dict[str, float] = field(default_factory=dict)
    outputs: dict[str, float] = field(default_factory=dict)
    drivers: dict[str, tuple[float, float]] = field(default_factory=dict)
    rate_scales: dict[str, float] | None = None
    output_scales: dict[str, float] | None = None
