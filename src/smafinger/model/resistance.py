"""A wire's electrical resistance, phase and temperature dependent: what self-sensing measures.

The resistivity of each phase is linear in temperature, and the wire's is the phase mix
(a rule of mixtures in the martensite fraction xi, as in the resistance model of the
Mueller-Achenbach-Seelecke SMA model, Furst and Seelecke 2012)::

    rho(xi, T) = xi rho_M (1 + alpha_M (T - T_ref)) + (1 - xi) rho_A (1 + alpha_A (T - T_ref))   (R1)

The wire's length follows the mechanism: its strain from the austenite length L_w is the
total strain of wire and series spring (Eq. 6) less the spring's elongation x_s,
eps = eps_0 + (path - path_0 - x_s) / L_w, with eps_0 = sigma_0 / D(xi_0) + eps_R xi_0 the
wire's own strain at the start (Eq. 7, theta_T = 0). (With the rate law, sigma / D + eps_R xi
drifts from this over cycles, D varying with xi; the geometric length is the one a resistance
measures.) At constant volume (the transformation strain is isochoric) L = L_w (1 + eps) and
A = S_w / (1 + eps), so::

    R = rho(xi, T) L / A = rho(xi, T) L_w (1 + eps)^2 / S_w                                    (R2)

Both effects lower the resistance when the wire contracts into austenite (about 18 % over a
full transformation with the default values), which is what lets a controller estimate the
stroke from the resistance alone. The Joule heating of Eq. (11) keeps the set's constant
``resistance_ohm_per_m`` (the paper's R_w): this model only *measures* the wire.

Default values (``parameters.base``): rho_A = 8.9e-7 ohm m, rho_M = 1.02e-6 ohm m,
alpha_A = 2e-4 /K, alpha_M = 3e-4 /K at T_ref = 20 degC, the resistance parameters published
with the MAS model for actuator-grade NiTi wire (docs/controllers.md, "Self-sensing").
"""

from ..jit import njit
from ..parameters.options import StressLaw
from .constitutive import rate_law_modulus, youngs_modulus
from .hysteresis import xi_on_branch
from .wire import algebraic_stress, total_strain


@njit(cache=True, forceinline=True)
def resistivity(wire, T_C, xi):
    """rho(xi, T) of Eq. (R1) [ohm m]."""
    dT = T_C - wire.resistivity_reference_C
    rho_A = wire.resistivity_austenite_ohm_m * (1.0 + wire.resistivity_tc_austenite_per_K * dT)
    rho_M = wire.resistivity_martensite_ohm_m * (1.0 + wire.resistivity_tc_martensite_per_K * dT)
    return xi * rho_M + (1.0 - xi) * rho_A


@njit(cache=True, forceinline=True)
def wire_strain(wire, path, spring_m):
    """The wire's own strain from its austenite length at tendon path ``path`` and spring
    elongation ``spring_m`` (see the module docstring); the initial one is eps_total0 less x_0 / L_w."""
    return wire.eps_total0 + (path - wire.path0_m - spring_m) / wire.wire_length_m


@njit(cache=True, forceinline=True)
def wire_resistance(wire, T_C, xi, strain):
    """The whole wire's resistance R [ohm] of Eq. (R2) at temperature, martensite fraction and strain."""
    stretch = 1.0 + strain
    return resistivity(wire, T_C, xi) * wire.wire_length_m * stretch * stretch / wire.area_m2


@njit(cache=True)
def resistance_at(wire, ws, branch, path, stress_law):
    """R [ohm] of a wire at its state ``ws`` on kinetics branch ``branch``, tendon path ``path``."""
    if stress_law == StressLaw.ALGEBRAIC:
        _, xi, x_s = algebraic_stress(wire, total_strain(wire, path), ws.T_C, branch)
    else:
        xi = xi_on_branch(branch, ws.T_C, ws.sigma_Pa, wire)[0]
        x_s = rate_law_modulus(wire, ws.sigma_Pa, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))[1]
    return wire_resistance(wire, ws.T_C, xi, wire_strain(wire, path, x_s))
