"""The oracle's right-hand side: Table I's coupled equations at one state, inputs held."""

from __future__ import annotations

from . import material as mat
from . import mechanics as mech
from . import thermal
from .model import Derivative, Held, OracleModel, Vars, Wire, WireHeld, WireVars


def _heat(m: OracleModel, w: Wire, ws: WireVars, wh: WireHeld, current: bool):
    """Eq. (11) without latent heat: (P' [W/m], h, surroundings, dT/dt, dT_case/dt, scale of dT/dt)."""
    P = thermal.joule_power_per_metre(wh.drive, current, m.whole_wire, w.R_per_m, w.L_w)
    h = thermal.convection(ws.T, *(w.h_heating if wh.heating else w.h_cooling))
    around = ws.T_case if m.two_node else w.T_amb
    dT = thermal.temperature_rate(ws.T, P, h, around, w.M_w, w.C_p, w.A_w)
    dT_case = (thermal.casing_rate(ws.T, ws.T_case, h, w.A_w, w.casing_loss, w.casing_capacity, w.T_amb)
               if m.two_node else 0.0)
    return P, h, around, dT, dT_case, (abs(P) + abs(h * w.A_w * (ws.T - around))) / (w.M_w * w.C_p)


def _stress(m: OracleModel, w: Wire, ws: WireVars, wh: WireHeld, path: float, strain_rate: float):
    """(sigma, xi's Fraction, spring elongation, s_free, s_T, D_eq): the stress law, sigma' = s_free + s_T T'."""
    if m.algebraic:  # sigma and xi solved from the strain (authors' 2020 model)
        eps = w.eps0 + mech.strain_change(path, w.path0, w.L_w)
        sigma, f, x_s = mat.algebraic_stress(eps, ws.T, wh.branch, w.transformation, w.D_A, w.D_M, w.eps_R,
                                             w.spring, w.S_w, w.L_w)
        s_free, s_T = mat.algebraic_law(eps, strain_rate, sigma, f, w.eps_R, w.D_A, w.D_M, w.spring, w.S_w, w.L_w)
        return sigma, f, x_s, s_free, s_T, 0.0
    sigma = ws.sigma  # Eqs. (7b)-(8)
    f = wh.branch.fraction(ws.T, sigma, w.transformation)
    D = mat.youngs_modulus(f.xi, w.D_A, w.D_M)
    if w.spring is None:
        x_s, D_eq = 0.0, D
    else:
        x_s = mat.spring_elongation(sigma * w.S_w, w.spring)
        D_eq = mat.series_modulus(mat.spring_stiffness(x_s, w.spring), D, w.S_w, w.L_w)
    s_free, s_T = mat.rate_law(D_eq, strain_rate, w.eps_R, f.xi_T, f.xi_s)
    return sigma, f, x_s, s_free, s_T, D_eq


def _stiffening(w: Wire, x_s: float) -> float:
    """Round-off scale of D_eq relative to D_eq from the spring elongation's: x K_s'(x) / K_s (Eq. 8).

    Far up the slack's cosh stiffening a relative error e in x becomes 1000 f x e in K_s,eff.
    """
    if w.spring is None:
        return 0.0
    return x_s * mat.spring_stiffness_slope(x_s, w.spring) / mat.spring_stiffness(x_s, w.spring)


def _temperature_and_stress_rates(m: OracleModel, w: Wire, sigma: float, f, s_free: float, s_T: float,
                                  dT_plain: float) -> tuple[float, float, float]:
    """(dT/dt, dsigma/dt of the state, dsigma/dt of the stress) with the latent heat.

    Rate law: T' and sigma' solved together; a slack tendon (sigma <= 0) does not push, so its
    stress does not fall and xi' = xi_T T' alone. Algebraic law (the model's choice: the stress
    is no state of it): the latent heat takes xi' = xi_T T'; its stress's rate is reported for
    the kinetics only.
    """
    r = w.latent_heat / w.C_p
    if m.algebraic:
        dT = thermal.with_latent_heat(dT_plain, r, f.xi_T, 0.0, 0.0, 0.0)
        return dT, 0.0, s_free + s_T * dT
    dT = thermal.with_latent_heat(dT_plain, r, f.xi_T, f.xi_s, s_free, s_T)
    dsigma = s_free + s_T * dT
    if sigma <= 0.0 and dsigma < 0.0:
        dT = thermal.with_latent_heat(dT_plain, r, f.xi_T, f.xi_s, 0.0, 0.0)
        dsigma = 0.0
    return dT, dsigma, dsigma


def _wire(m: OracleModel, w: Wire, ws: WireVars, wh: WireHeld, geo, v: float, current: bool, d: Derivative,
          prefix: str) -> float:
    """One wire's rates and outputs into ``d``; returns its generalized force (F times the arm)."""
    path, dpath, arm = geo
    P, h, around, dT_plain, dT_case, plain_scale = _heat(m, w, ws, wh, current)
    strain_rate = dpath * v / w.L_w  # Eq. (6)
    sigma, f, x_s, s_free, s_T, D_eq = _stress(m, w, ws, wh, path, strain_rate)
    dT, dsigma, stress_rate = _temperature_and_stress_rates(m, w, sigma, f, s_free, s_T, dT_plain)
    power = thermal.terminal_power(wh.drive, current, w.R_per_m, w.L_w)
    force = sigma * w.S_w
    d.rates.update({prefix + "T": dT, prefix + "sigma": dsigma, prefix + "electrical": power,
                    prefix + "heat": P * w.L_w, prefix + "T_case": dT_case})
    d.drivers[w.name] = (dT, stress_rate)
    outputs = {"xi": f.xi, "sigma": sigma, "force": force, "spring": x_s, "arm": abs(arm)}
    for k, value in outputs.items():
        d.outputs[prefix + k] = value
    if d.rate_scales is not None:
        r = w.latent_heat / w.C_p
        den_s = abs(1.0 + D_eq * w.eps_R * f.xi_s)
        s_T_scale = D_eq * w.eps_R * f.amp_T / den_s  # 0 for the algebraic law
        T_num = plain_scale + (0.0 if m.algebraic else r * f.amp_s * abs(s_free))
        T_den = abs(1.0 - r * f.xi_T - (0.0 if m.algebraic else r * f.xi_s * s_T))
        T_scale = (T_num + abs(dT) * (1.0 + r * f.amp_T + r * f.amp_s * s_T_scale)) / T_den
        # the stress rate: numerator and denominator each to round-off of their terms, and T' to its own
        sigma_scale = (0.0 if m.algebraic else (D_eq * (abs(strain_rate) + w.eps_R * f.amp_T * (abs(dT) + T_scale))
                                                 + abs(dsigma) * D_eq * w.eps_R * f.amp_s) / den_s
                       + abs(dsigma) * _stiffening(w, x_s))
        case_scale = (abs(h * w.A_w * (ws.T - ws.T_case)) + abs(w.casing_loss * (ws.T_case - w.T_amb))) / \
            w.casing_capacity if m.two_node else 0.0
        d.rate_scales.update({prefix + "T": T_scale, prefix + "sigma": sigma_scale, prefix + "electrical": power,
                              prefix + "heat": abs(P) * w.L_w, prefix + "T_case": case_scale})
    if d.output_scales is not None:  # outputs: the scale of a value is its size (xi: 1)
        d.output_scales.update({prefix + k: (1.0 if k == "xi" else abs(value)) for k, value in outputs.items()})
    return force * arm


def derivative(m: OracleModel, s: Vars, u: Held, scales: bool = False) -> Derivative:
    """Rates of every state component and the algebraic outputs (and, if ``scales``, their scales).

    Names: ``q``, ``v``, ``error_integral``, ``<wire>.T``, ``<wire>.sigma``, ``<wire>.electrical``,
    ``<wire>.heat``, ``<wire>.T_case`` (rates); ``load``, ``<wire>.xi``, ``<wire>.sigma``,
    ``<wire>.force``, ``<wire>.spring``, ``<wire>.arm`` (outputs, ``arm`` being |b| of Eqs. 4b/5b,
    1 for the slider). The scale of a value is the sum of the magnitudes of the terms it is
    computed from: its round-off is a few units of 1e-16 of that.
    """
    d = Derivative(rate_scales={} if scales else None, output_scales={} if scales else None)
    mc = m.mechanism
    terms = [_wire(m, w, ws, wh, geo, s.v, u.current, d, w.name + ".")
             for w, ws, wh, geo in zip(m.wires, s.wires, u.wires, mc.wire_geometry(s.q))]
    external = mc.external(s.q)
    load = sum(terms) + external  # Eq. (1b)
    d.outputs["load"] = load
    d.rates["q"] = 0.0 if u.stuck else s.v
    d.rates["v"] = mech.acceleration(load, s.v, u.stuck, mc.inertia, mc.dynamic, u.viscous)
    d.rates["error_integral"] = (u.q_target - s.q) * u.integrating
    if scales:
        load_scale = sum(abs(f) for f in terms) + abs(external)
        friction = 0.0 if u.stuck else mech.sliding_friction(s.v, mc.dynamic, u.viscous)
        d.output_scales["load"] = load_scale
        d.rate_scales.update({"q": abs(s.v), "v": (load_scale + abs(friction)) / mc.inertia,
                              "error_integral": (abs(u.q_target) + abs(s.q)) * abs(u.integrating)})
    return d
