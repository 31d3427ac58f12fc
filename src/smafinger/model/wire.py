"""One SMA wire: its stress, martensite fraction and temperature rate (Eqs. 6-11 together).

The wire's total strain follows the mechanism (Eq. 6: Delta eps = Delta path / L_w), its
martensite fraction the kinetics branch (Eqs. 9-10), its stress the constitutive law (Eqs. 7-8,
rate or algebraic form) and its temperature the heat balance (Eq. 11).
"""

from ..jit import njit
from ..parameters.options import StressLaw
from .constitutive import rate_law_modulus, secant_modulus, stress_rate, youngs_modulus
from .heat import casing_temperature_rate, latent_heat_rate, wire_temperature_rate
from .hysteresis import xi_on_branch


@njit(cache=True)
def _secant_stress(wire, eps_total, T, branch, sigma):
    """S(sigma) = D_eq (eps - eps_R xi) with xi = xi(T, sigma): the stress the strain implies.

    Returns (S, xi, spring elongation). With D_M <= D_A (NiTi's phases) S decreases as sigma
    grows (more stress, more martensite, less elastic strain and a softer wire), so sigma =
    S(sigma) has exactly one root. With a martensite stiffer than the austenite S can rise
    (:func:`_bracketed_stress` widens its bracket); it never exceeds max(D_A, D_M) eps_total.
    """
    xi = xi_on_branch(branch, T, sigma, wire)[0]
    eps_el = eps_total - wire.eps_R * xi
    if eps_el <= 0.0:
        return 0.0, xi, 0.0
    D_eq, x_s = secant_modulus(wire, eps_el, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))
    return D_eq * eps_el, xi, x_s


@njit(cache=True)
def _bracketed_stress(wire, eps_total, T, branch):
    """A root of sigma - S(sigma) by the Illinois method on [0, S(0)] (always converges).

    Where S rises with sigma (a martensite stiffer than the austenite, :func:`_secant_stress`)
    S(0) may be below the root: then the bracket's top is S's bound max(D_A, D_M) eps_total,
    where sigma - S(sigma) >= 0 (found by review: with D_A = 1e8 Pa both ends were below the
    root, and the method stepped outside them to -81 MPa, a wire in compression).
    """
    lo, g_lo = 0.0, -_secant_stress(wire, eps_total, T, branch, 0.0)[0]
    if g_lo >= 0.0:
        return 0.0
    hi = -g_lo
    g_hi = hi - _secant_stress(wire, eps_total, T, branch, hi)[0]
    if g_hi < 0.0:  # S(0) is below the root: S rose on the way
        lo, g_lo = hi, g_hi
        hi = max(wire.D_A_Pa, wire.D_M_Pa) * eps_total
        g_hi = hi - _secant_stress(wire, eps_total, T, branch, hi)[0]
    side = 0
    x = hi
    for _ in range(100):
        if g_hi == g_lo:
            break
        x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo)
        g = x - _secant_stress(wire, eps_total, T, branch, x)[0]
        if abs(g) <= 1e-9 * (1.0 + abs(x)) or hi - lo <= 1e-12 * (1.0 + hi):
            break
        if g > 0.0:
            hi, g_hi = x, g
            if side == 1:
                g_lo *= 0.5
            side = 1
        else:
            lo, g_lo = x, g
            if side == -1:
                g_hi *= 0.5
            side = -1
    return x


@njit(cache=True)
def algebraic_stress(wire, eps_total, T, branch):
    """Authors' 2020 law: sigma = D_eq (eps - eps_R xi), solved together with xi(T, sigma).

    Fixed-point iteration first (through a spring-slack tendon the xi-sigma coupling is weak,
    contraction about 0.05: a few iterations, as in the authors' model); if it has not
    converged in 12 (a wire pulling directly is a hundred times stiffer), the root is bracketed
    instead (:func:`_bracketed_stress`). Returns (sigma, xi, spring elongation).
    """
    sigma = 0.0
    x_s = 0.0
    for _ in range(12):
        sigma_new, _, x_s = _secant_stress(wire, eps_total, T, branch, sigma)
        if abs(sigma_new - sigma) <= 1e-9 * (1.0 + abs(sigma_new)):
            # converged: xi at the solution, the spring as the last iterate left it
            return sigma_new, xi_on_branch(branch, T, sigma_new, wire)[0], x_s
        sigma = sigma_new
    sigma = _bracketed_stress(wire, eps_total, T, branch)
    _, xi, x_s = _secant_stress(wire, eps_total, T, branch, sigma)
    return sigma, xi, x_s


@njit(cache=True, forceinline=True)
def total_strain(wire, path):
    """Total strain of wire + spring at path length ``path`` (Eq. 6), for the algebraic law."""
    return wire.eps_total0 + (path - wire.path0_m) / wire.wire_length_m


@njit(cache=True, forceinline=True)
def wire_stress_xi(wire, ws, branch, path, stress_law):
    """(sigma, xi) of a wire at its state: the state's stress (rate law) or the solved one."""
    if stress_law == StressLaw.ALGEBRAIC:
        s, xi, _ = algebraic_stress(wire, total_strain(wire, path), ws.T_C, branch)
        return s, xi
    return ws.sigma_Pa, xi_on_branch(branch, ws.T_C, ws.sigma_Pa, wire)[0]


@njit(cache=True, forceinline=True)
def algebraic_stress_rate(wire, T, sigma, branch, dT_dt, dpath_dt):
    """The stress rate of the algebraic law at its solution ``sigma``: Eq. (7b)'s dsigma/dt there
    (with dxi/dt = xi_T T' + xi_sigma sigma' on ``branch``) for path rate ``dpath_dt`` [m/s]
    (Eq. 6). The stress is no state under that law, so the state's rate is 0; this is the rate
    tau = T - sigma/c moves with, which the kinetics' direction needs (MODEL-NOTES)."""
    xi, xT, xs = xi_on_branch(branch, T, sigma, wire)
    D_eq = rate_law_modulus(wire, sigma, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))[0]
    return stress_rate(D_eq, dpath_dt / wire.wire_length_m, wire.eps_R, xT, xs, dT_dt, sigma)


@njit(cache=True, forceinline=True)
def _strain_driven(wire, dT0, D_eq, deps, xT, xs, sigma):
    """(dT/dt, dsigma/dt, dxi/dt) of the rate law at strain rate ``deps`` (Eqs. 7b, 11 with the
    latent heat): T' and sigma' solved together, dxi/dt = xi_T T' + xi_sigma sigma'. A slack
    tendon's stress rate is floored at 0 (:func:`stress_rate`): its T' is then solved with
    sigma' = 0, so that the latent heat takes dxi/dt = xi_T T' alone (it took xi_sigma times the
    unfloored rate, 8 % on dT/dt in the oracle's case, tests/test_oracle.py)."""
    den = 1.0 + D_eq * wire.eps_R * xs
    dT = latent_heat_rate(dT0, D_eq * deps / den, D_eq * wire.eps_R * xT / den, xT, xs, wire)
    dsigma = stress_rate(D_eq, deps, wire.eps_R, xT, xs, dT, sigma)
    if sigma <= 0.0 and dsigma == 0.0:  # slack and held there: no stress rate to couple
        dT = latent_heat_rate(dT0, 0.0, 0.0, xT, xs, wire)
    return dT, dsigma, xT * dT + xs * dsigma


@njit(cache=True, forceinline=True)
def wire_rates(wire, ws, wi, route_now, v, current_drive, opts):
    """A wire's (dT/dt, dsigma/dt, dT_case/dt, dxi/dt), (sigma, xi, spring elongation) and the
    rates' growth per unit of the mechanism's rate v.

    ``route_now``: the wire's :class:`~smafinger.model.kinematics.WireGeometry` at the current q;
    ``wi`` the wire's held inputs.
    Rate law: dsigma/dt of Eq. (7b) with dxi/dt = xi_T T' + xi_sigma sigma' (returned: the rate of
    the state's ``xi_integrated``); with the latent heat on, T' and sigma' are solved together.
    Algebraic law: sigma solved with xi; the latent heat then takes dxi/dt = xi_T T' (sigma's own
    rate is not part of the state); the returned dxi/dt is 0 (no stress to catch up).

    The rates of T, sigma and xi_integrated are affine in v (Eq. 6) while the wire is taut: their
    growth per unit of v, (d/dv of dT/dt, dsigma/dt, dxi/dt), is the last value returned, for an
    integrator that moves the mechanism at another rate than v over a step
    (:func:`smafinger.engine.integrators.step`). Zeros when the tendon is slack (sigma <= 0: the
    stress rate is floored there, not affine) and with the algebraic law (no stress rate).
    """
    path, dpath = route_now.path_m, route_now.dpath_dq
    T = ws.T_C
    dT0 = wire_temperature_rate(wire, T, ws.T_case_C, wi.drive, wi.heating, current_drive, opts)
    dTc = casing_temperature_rate(wire, T, ws.T_case_C, wi.heating, opts)
    if opts.stress_law == StressLaw.ALGEBRAIC:
        sigma, xi, x_s = algebraic_stress(wire, total_strain(wire, path), T, wi.branch)
        if wire.latent_heat_J_kg != 0.0:
            dT0 = latent_heat_rate(dT0, 0.0, 0.0, xi_on_branch(wi.branch, T, sigma, wire)[1], 0.0, wire)
        return dT0, 0.0, dTc, 0.0, sigma, xi, x_s, (0.0, 0.0, 0.0)
    sigma = ws.sigma_Pa
    xi, xT, xs = xi_on_branch(wi.branch, T, sigma, wire)
    D_eq, x_s = rate_law_modulus(wire, sigma, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))
    deps = dpath * v / wire.wire_length_m  # Eq. (6): Delta eps = Delta path / L_w
    dT, dsigma, dxi = _strain_driven(wire, dT0, D_eq, deps, xT, xs, sigma)
    per_v = (0.0, 0.0, 0.0)
    if sigma > 0.0:  # the rates one unit of v further on, less these: exact while they are affine
        dT1, dsigma1, dxi1 = _strain_driven(wire, dT0, D_eq, dpath * (v + 1.0) / wire.wire_length_m, xT, xs, sigma)
        per_v = (dT1 - dT, dsigma1 - dsigma, dxi1 - dxi)
    return dT, dsigma, dTc, dxi, sigma, xi, x_s, per_v


@njit(cache=True, forceinline=True)
def transformation_catch_up(wire, ws, branch):
    """Eq. (7b) over a sub-step: (sigma, xi_integrated) once the stress has taken the sub-step's
    whole transformation increment.

    The rate law integrates dsigma/dt = D_eq (deps/dt - eps_R dxi/dt) with dxi/dt = xi_T T' +
    xi_sigma sigma'; ``ws.xi_integrated`` is that dxi/dt integrated alongside (from xi at the
    sub-step start), while xi itself is the kinetics branch's value at (T, sigma). Where xi is
    smooth over the sub-step the two agree to the integrator's order. The return-point memory makes
    xi piecewise within a sub-step (held while tau is back from its extreme, then on the branch,
    then on the parent past a target: a kink in every PWM period of a slow transformation), and a
    fixed-step quadrature of dxi/dt across a kink misses an O(1) share of the increment after it:
    the stress then lags the transformation strain for good. The stress takes the rest,
    dxi = xi - xi_integrated, as Eq. (7b) does with xi's own dependence on sigma:
    dsigma = -D_eq eps_R dxi / (1 + D_eq eps_R xi_sigma), D_eq at the sub-step's end (Eq. 8).
    """
    xi, _, xs = xi_on_branch(branch, ws.T_C, ws.sigma_Pa, wire)
    missed = xi - ws.xi_integrated
    if missed == 0.0:
        return ws.sigma_Pa, xi
    D_eq = rate_law_modulus(wire, ws.sigma_Pa, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))[0]
    k = D_eq * wire.eps_R
    dsigma = -k * missed / (1.0 + k * xs)
    return ws.sigma_Pa + dsigma, xi + xs * dsigma
