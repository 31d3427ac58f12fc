"""The oracle's right-hand side: Table I's coupled equations at one state, inputs held."""

from __future__ import annotations

from . import material as mat
from . import mechanics as mech
from .model import Derivative, Held, OracleModel, Vars, Wire, WireHeld, WireVars


def _wire(m: OracleModel, w: Wire, ws: WireVars, wh: WireHeld, geo, v: float, current: bool, d: Derivative,
          prefix: str) -> float:
    """One wire's rates and outputs into ``d``; returns its generalized force (F times the arm)."""
    path, dpath, arm = geo
    sc = d.rate_scales
    # Eq. (11)
    P = mech.joule_power_per_metre(wh.drive, current, m.whole_wire, w.R_per_m, w.L_w)
    h = mech.convection(ws.T, *(w.h_heating if wh.heating else w.h_cooling))
    dT = mech.temperature_rate(ws.T, P, h, w.T_amb, w.M_w, w.C_p, w.A_w)
    power = mech.terminal_power(wh.drive, current, w.R_per_m, w.L_w)
    if m.algebraic:  # sigma and xi solved from the strain (authors' 2020 model)
        eps = w.eps0 + mech.strain_change(path, w.path0, w.L_w)
        sigma, xi, x_s = mat.algebraic_stress(eps, ws.T, wh.kinetics, w.transformation, w.D_A, w.D_M, w.eps_R,
                                              w.spring, w.S_w, w.L_w)
        dsigma = 0.0
        if sc is not None:
            sc[prefix + "sigma"] = 0.0
    else:  # Eqs. (7b)-(8)
        sigma = ws.sigma
        xi, xi_T, xi_s = mat.martensite_fraction(wh.kinetics, ws.T, sigma, w.transformation)
        D = mat.youngs_modulus(xi, w.D_A, w.D_M)
        if w.spring is None:
            x_s, D_eq = 0.0, D
        else:
            x_s = mat.spring_elongation(sigma * w.S_w, w.spring)
            D_eq = mat.series_modulus(mat.spring_stiffness(x_s, w.spring), D, w.S_w, w.L_w)
        strain_rate = dpath * v / w.L_w  # Eq. (6)
        dsigma = mat.stress_rate(D_eq, strain_rate, w.eps_R, xi_T, xi_s, dT, sigma)
        if sc is not None:  # numerator and denominator each to round-off of their terms
            amp_T, amp_s = mat.partial_amplitudes(wh.kinetics, ws.T, sigma, w.transformation)
            sc[prefix + "sigma"] = ((D_eq * (abs(strain_rate) + w.eps_R * amp_T * abs(dT))
                                     + abs(dsigma) * D_eq * w.eps_R * amp_s) / abs(1.0 + D_eq * w.eps_R * xi_s))
    force = sigma * w.S_w
    d.rates.update({prefix + "T": dT, prefix + "sigma": dsigma, prefix + "energy": power})
    if sc is not None:
        sc[prefix + "T"] = (abs(P) + abs(h * w.A_w * (ws.T - w.T_amb))) / (w.M_w * w.C_p)
        sc[prefix + "energy"] = power
    outputs = {"xi": xi, "sigma": sigma, "force": force, "spring": x_s, "arm": abs(arm)}
    for k, value in outputs.items():
        d.outputs[prefix + k] = value
    if d.output_scales is not None:  # outputs: the scale of a value is its size (xi: 1)
        d.output_scales.update({prefix + k: (1.0 if k == "xi" else abs(value)) for k, value in outputs.items()})
    return force * arm


def derivative(m: OracleModel, s: Vars, u: Held, scales: bool = False) -> Derivative:
    """Rates of every state component and the algebraic outputs (and, if ``scales``, their scales).

    Names: ``q``, ``v``, ``error_integral``, ``<wire>.T``, ``<wire>.sigma``, ``<wire>.energy``
    (rates); ``load``, ``<wire>.xi``, ``<wire>.sigma``, ``<wire>.force``, ``<wire>.spring``,
    ``<wire>.arm`` (outputs, ``arm`` being |b| of Eqs. 4b/5b, 1 for the slider). The scale of a
    value is the sum of the magnitudes of the terms it is computed from: its round-off is a
    few units of 1e-16 of that.
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
