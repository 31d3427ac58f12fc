"""Warnings for physically absurd results, from a run's exported signals.

The model integrates whatever it is given: 100 V on the paper's wire gives 1,252 degC, a
1e6 N/m spring a wire stress of 73 GPa. Neither is an error of the numerics, but no real wire
survives either. :func:`check` flags, per wire:

- **overheating**: the temperature far above the stress-shifted austenite finish temperature,
  ``T > A_F(sigma) + OVERHEAT_MARGIN_C`` with ``A_F(sigma) = A_F0 + sigma / c_A`` (Eq. 9).
  Past A_F the wire is fully austenite; running it much hotter ages or anneals NiTi and only
  heats the room, so the drive or the heat transfer is likely wrong;
- **overstress**: the stress above :data:`STRESS_RATING_PA`, the top of the usual rating of
  NiTi actuator wire in repeated use;
- **overstrain**: the wire's strain ``sigma / D(xi) + xi eps_R`` (Eq. 7a with theta_T = 0)
  beyond the recoverable strain eps_R by more than :data:`STRAIN_MARGIN`: the wire would
  deform plastically, which the model does not describe;
- **a start outside the loop**: ``xi_init`` outside the major hysteresis loop at ``T_init_C``
  (say fully martensite at 100 degC): the kinetics place it on the loop at t = 0, so the run
  starts from another xi than the set names;
- **no such wire** (found by review: each was returned without a word): xi outside [0, 1] (the
  ``authors2020`` rule's start formulas do not clip it, docs/hysteresis.md); a wire in
  compression, which a wire cannot take; a wire colder than anything can cool it (below both
  the ambient and its start, with no latent heat to absorb), or a casing colder than its air
  and its wire: a numerical instability, the run's numbers finite;
- **a joint turned over**: the angle beyond +-:data:`JOINT_RANGE_DEG`;
- **a heating resistance that is not this wire's**: Eq. (11) heats with the set's
  ``resistance_ohm_per_m``, while the wire's resistivities (``model.resistance``, Eq. R1) give
  another at its diameter: more than :data:`RESISTANCE_MISMATCH` times apart (a changed
  ``wire_diameter_m`` alone heated a 0.25 mm wire with the 0.5 mm wire's 4.1 ohm/m, 5x the
  power its resistance gives; found by review). The named sets are within 1.27x.

The warnings go into the run's metrics (``warnings``: a list of one-line texts) and so into
every summary; the command line prints them.
"""

from __future__ import annotations

import numpy as np

#: overheating: this far above the stress-shifted A_F [degC]
OVERHEAT_MARGIN_C = 100.0
#: overstress: above this wire stress [Pa] (NiTi actuator wire is rated for about 100-200 MPa
#: in repeated use)
STRESS_RATING_PA = 200e6
#: overstrain: this far beyond eps_R [-] (1 % strain)
STRAIN_MARGIN = 0.01
#: a first sample of xi this far from xi_init: the start was placed onto the major loop
XI_START_TOLERANCE = 1e-6
#: xi this far outside [0, 1]: a martensite fraction no wire has
XI_RANGE_TOLERANCE = 1e-9
#: a wire stress below this [Pa]: the wire pushes (rounding tolerated)
COMPRESSION_PA = -1e3
#: a temperature this far below the coldest it can cool to [degC]
COLD_MARGIN_C = 1.0
#: a joint angle beyond +- this [deg]: the finger has turned over
JOINT_RANGE_DEG = 180.0
#: the heating resistance and the resistivities' this many times apart (either way)
RESISTANCE_MISMATCH = 1.5


def austenite_finish_C(sigma_Pa: np.ndarray, A_F0_C: float, c_A_Pa_per_C: float) -> np.ndarray:
    """The stress-shifted austenite finish temperature A_F = A_F0 + sigma / c_A (Eq. 9)."""
    return A_F0_C + sigma_Pa / c_A_Pa_per_C


def wire_strain(sigma_Pa: np.ndarray, xi: np.ndarray, D_A_Pa: float, D_M_Pa: float, eps_R: float) -> np.ndarray:
    """The wire's strain sigma / D(xi) + xi eps_R (Eq. 7a with theta_T = 0)."""
    from .model.constitutive import youngs_modulus

    modulus = getattr(youngs_modulus, "py_func", youngs_modulus)  # the plain function (numpy arrays)
    return sigma_Pa / modulus(xi, D_A_Pa, D_M_Pa) + xi * eps_R


def _peak(values: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """(largest value ignoring NaN, its time); the first of equal largest values."""
    i = int(np.argmax(values))  # the first NaN if there is one: then look again without them
    if np.isnan(values[i]):
        i = int(np.nanargmax(values))
    return float(values[i]), float(t[i])


def check(result) -> list[str]:
    """The plausibility warnings of a run (empty: nothing absurd), one line each."""
    p = result.spec.params
    t = result.t
    out = []
    for w in p.wire_names:
        T, sigma, xi = (result.signal(n) for n in (f"T_{w}_C", f"sigma_{w}_Pa", f"xi_{w}"))
        if abs(float(xi[0]) - p.xi_init) > XI_START_TOLERANCE:
            out.append(f"{w} wire: xi_init = {p.xi_init:g} lies outside the major hysteresis loop at T_init_C = "
                       f"{p.T_init_C:g} degC and the initial stress; the run starts from xi = {float(xi[0]):.4g} "
                       "(the loop's bound there)")
        over, at = _peak(T - austenite_finish_C(sigma, p.A_F0_C, p.c_A_Pa_per_C), t)
        if over > OVERHEAT_MARGIN_C:
            out.append(f"{w} wire: {np.nanmax(T):.0f} degC, {over:.0f} degC above its austenite finish "
                       f"temperature A_F at t = {at:.3g} s: far outside what the wire survives; check the "
                       "drive (voltage, duty or current) and the heat transfer (h0, h2)")
        peak, at = _peak(sigma, t)
        if peak > STRESS_RATING_PA:
            out.append(f"{w} wire: stress {peak / 1e6:,.0f} MPa at t = {at:.3g} s, above the "
                       f"{STRESS_RATING_PA / 1e6:.0f} MPa NiTi actuator wire is rated for; check the "
                       "springs and the load")
        strain, at = _peak(wire_strain(sigma, xi, p.D_A_Pa, p.D_M_Pa, p.eps_R), t)
        if strain > p.eps_R + STRAIN_MARGIN:
            out.append(f"{w} wire: strain {strain:.3g} at t = {at:.3g} s, beyond the recoverable strain "
                       f"eps_R = {p.eps_R:g} (+{STRAIN_MARGIN:g}): the wire would deform plastically, "
                       "which the model does not describe")
        out += _impossible_wire(result, p, w, xi, sigma, T, t)
    if p.mechanism == "joint":
        peak, at = _peak(np.abs(result.theta_deg), t)
        if peak > JOINT_RANGE_DEG:
            out.append(f"joint angle {peak:,.4g} deg at t = {at:.3g} s, beyond +-{JOINT_RANGE_DEG:g} deg: the finger "
                       "has turned over; a numerical instability (check dt_s and the method) or a drive far too strong")
    out += _resistance_mismatch(p)
    if p.V_L_V > 0.0 and len(p.wire_names) > 1:  # the joint's two wires pull against each other
        out.append(f"V_L_V = {p.V_L_V:g} V drives every wire whose duty is 0 (Fig. 6's low level): the opposing "
                   "wires are heated at once whenever one is not pulsed, which the interlock counter, counting "
                   "drives above V_L, does not count")
    return out


def _resistance_mismatch(p) -> list[str]:
    """The warning of a heating resistance the wire's resistivities do not give (at the start)."""
    import math

    from .model.build import build_model
    from .model.resistance import resistivity

    wire = build_model(p).wires[0]  # every wire has the set's electrical fields
    rho = getattr(resistivity, "py_func", resistivity)  # the plain function (numba's JIT may be off)
    per_m = rho(wire, p.T_init_C, p.xi_init) / wire.area_m2
    ratio = per_m / p.resistance_ohm_per_m
    if max(ratio, 1.0 / ratio) <= RESISTANCE_MISMATCH or not math.isfinite(ratio):
        return []
    return [f"resistance_ohm_per_m = {p.resistance_ohm_per_m:g} ohm/m heats the wire (Eq. 11), but its resistivities "
            f"give {per_m:.4g} ohm/m at its diameter of {1e3 * p.wire_diameter_m:g} mm ({ratio:.3g}x): set "
            "resistance_ohm_per_m for this wire (the R_*_ohm signals and self-sensing use the resistivities)"]


def _impossible_wire(result, p, w: str, xi, sigma, T, t) -> list[str]:
    """The warnings of values no wire has: xi outside [0, 1], compression, cooling below what can cool it."""
    out = []
    hi, at_hi = _peak(xi, t)
    lo, at_lo = _peak(-xi, t)
    lo = -lo
    if hi > 1.0 + XI_RANGE_TOLERANCE or lo < -XI_RANGE_TOLERANCE:
        value, at = (hi, at_hi) if hi > 1.0 + XI_RANGE_TOLERANCE else (lo, at_lo)
        why = (" (the authors2020 rule's start formulas do not clip it, docs/hysteresis.md)"
               if p.hysteresis == "authors2020" else "")
        out.append(f"{w} wire: xi = {value:.4g} at t = {at:.3g} s, outside [0, 1]: a martensite fraction no wire "
                   f"has{why}")
    least, at = _peak(-sigma, t)
    if -least < COMPRESSION_PA:
        out.append(f"{w} wire: stress {-least / 1e6:.4g} MPa at t = {at:.3g} s: the wire pushes, which a wire cannot")
    coldest = min(p.T_amb_C, p.T_init_C) - COLD_MARGIN_C
    cold, at = _peak(-T, t)
    if p.latent_heat_J_kg == 0.0 and -cold < coldest:
        out.append(f"{w} wire: {-cold:.4g} degC at t = {at:.3g} s, colder than the ambient and its start "
                   f"({min(p.T_amb_C, p.T_init_C):g} degC) with nothing to cool it: a numerical instability "
                   "(check dt_s and the method)")
    case, at = _peak(-result.signal(f"T_casing_{w}_C"), t)
    if -case < min(coldest, float(np.nanmin(T)) - COLD_MARGIN_C):
        out.append(f"{w} casing: {-case:.4g} degC at t = {at:.3g} s, colder than its air and its wire: a numerical "
                   "instability (check dt_s and the method; a small casing_heat_capacity_J_mK makes the casing "
                   "node stiff)")
    return out


# ---------------------------------------------------------------------------------------
# what to change after a numerical blow-up
# ---------------------------------------------------------------------------------------
#: the reference set of each mechanism: a parameter this many times away from it looks extreme
REFERENCE_SETS = {"joint": "paper2010", "linear-bias-spring": "linear-bias-spring"}
EXTREME_FACTOR = 10.0


def extreme_parameters(params) -> list[str]:
    """The parameters of a set furthest from its mechanism's reference set (at least
    :data:`EXTREME_FACTOR` times larger or smaller), furthest first, as ``NAME = VALUE`` texts."""
    import math

    from .parameters import get

    ref_name = REFERENCE_SETS.get(params.mechanism)
    if ref_name is None:
        return []
    ref = get(ref_name)
    found = []
    for name in params.field_names():
        v, r = getattr(params, name), getattr(ref, name)
        if isinstance(v, str) or isinstance(v, bool) or not (v > 0 and r > 0):
            continue
        factor = max(v / r, r / v)
        if factor >= EXTREME_FACTOR:
            found.append((factor, f"{name} = {v:g} ({'%.0f' % factor}x {'above' if v > r else 'below'} "
                                  f"{ref_name}'s {r:g})"))
    return [text for factor, text in sorted(found, key=lambda x: -x[0]) if math.isfinite(factor)]




def hinted(spec, run, style: str = "cli"):
    """``run()`` (a run of ``spec``), a numerical blow-up's message saying what to change
    (:func:`blowup_hint` in ``style``); a duty that is not a number as it is (the step is not
    what to change)."""
    from .engine.run import DutyNotANumber, SimulationError

    try:
        return run()
    except DutyNotANumber:
        raise
    except SimulationError as exc:
        raise SimulationError(f"{exc}; {blowup_hint(spec, style)}") from None


#: how a hint names the step and the method: the command line's options, the Python API's arguments, a sweep file's keys
HINT_STYLES = {"cli": ("--dt", "--method {}"), "api": ("dt_s", "method='{}'"), "toml": ("dt_s", 'method = "{}"')}


def blowup_hint(spec, style: str = "cli") -> str:
    """What to change after a run blew up: the step, the method, the parameter that looks
    extreme; named as options (``style="cli"``), as :func:`smafinger.simulate`'s arguments
    (``"api"``) or as a sweep file's keys (``"toml"``)."""
    from .engine.numerics import damping_rate_per_s, damping_step_limit

    dt, method = HINT_STYLES[style]
    limit = damping_step_limit(spec.params, spec.method)
    if limit is not None and spec.dt_s > limit:
        hint = (f"{spec.method} is stable only up to dt = {limit * 1e3:.2g} ms against this set's damping "
                f"({damping_rate_per_s(spec.params):.4g} 1/s; now {spec.dt_s * 1e3:g} ms): use a smaller {dt} or "
                f"{method.format('exponential')}")
    else:
        hint = f"try a smaller {dt} (now {spec.dt_s:g} s)"
        if spec.method != "rk4":
            hint += f" or {method.format('rk4')}"
    extreme = extreme_parameters(spec.params)
    if extreme:
        hint += f"; check {extreme[0]}"
    return hint
