"""A straightforward SciPy implementation of the same model, for benchmarks only.

Plain Python (``math``/``numpy``, no numba) right-hand side of Eqs. (1)-(11) for an open-loop
voltage program (piecewise-constant volts per wire, as the engine's ``voltage="T:VU:VL,..."``;
e.g. ``"0:8:0,6:0:0"``: the upper wire at 8 V for 6 s, then off), integrated by
``scipy.integrate.solve_ivp``.

It mirrors the engine's model options for the rate stress law (``stress_law = "rate"``),
re-sticking friction (``friction_sticking = "restick"``), ``damping_switch =
"heating-phase"`` and branch switching on the sign of dT/dt (``minor_loop_reversal_C = 0``):
the ``paper2010`` set with ``minor_loop_reversal_C = 0``:

- kinetics branch per wire from the sign of dT/dt at each step of the program (at constant
  voltage the sign cannot change within a step): heating branch while heating, cooling
  branch while cooling, with the branch's start value re-solved at the switch so that xi is
  continuous; an idle wire at ambient holds its xi;
- heat-transfer coefficients: the heating values while a wire is driven, the cooling ones
  otherwise; C_DF heating while a wire is driven, cooling otherwise;
- stick/slip (Eq. 2) with solve_ivp events: a stuck joint breaks away when |M_E| rises
  through M_SF; a sliding joint sticks when |omega| <= omega_stick while |M_E| <= M_SF.

Usage: ``simulate_baseline(get("paper2010").replace(minor_loop_reversal_C=0.0), "0:8:0,6:0:0")`` returns
(t, theta [deg], info).
"""

from __future__ import annotations

import math
import time
from functools import partial

import numpy as np
from scipy.integrate import solve_ivp

HOLD, HEATING, COOLING = 0, 1, 2
STUCK, SLIDING, CREEPING = "stuck", "sliding", "creeping"  # creeping: |omega| <= omega_stick, |M_E| > M_SF


class Model:
    """Derived constants of one parameter set, and the plain-Python equations."""

    def __init__(self, p):
        if (p.stress_law != "rate" or p.friction_sticking != "restick" or p.damping_switch != "heating-phase"
                or getattr(p, "minor_loop_reversal_C", 0.0) != 0.0):
            raise ValueError("the baseline implements stress_law='rate', friction_sticking='restick', "
                             "damping_switch='heating-phase', minor_loop_reversal_C=0 only")
        self.p = p
        self.S_w = math.pi * p.wire_diameter_m ** 2 / 4.0
        self.M_w = p.wire_density_kg_m3 * self.S_w
        self.A_w = math.pi * p.wire_diameter_m
        self.L_w = p.wire_length_m
        self.r = math.hypot(p.a1_m, p.a3_m)
        self.a0u = math.atan2(p.a1_m, p.a3_m)
        self.a0l = math.atan2(-p.a1_m, p.a3_m)
        self.theta0 = math.radians(p.theta0_deg)
        K = p.spring_K_N_m
        x_l = p.spring_length_lower_m - p.spring_free_length_m
        if p.spring_init == "given":
            x_u = p.spring_length_upper_m - p.spring_free_length_m
        else:  # friction-free moment balance at theta0 (Eq. 1b with M_E = 0)
            _, _, b_u, _, _, b_l = self.tendons(self.theta0)
            F_u = (K * x_l * b_l + p.mass_kg * p.gravity_m_s2 * p.d_CM_m * math.cos(self.theta0)) / b_u
            x_u = F_u / K
        self.xlim_u = x_u + p.slack_m - p.slack_band_m
        self.xlim_l = x_l + p.slack_m - p.slack_band_m
        self.sigma0_u = K * x_u / self.S_w
        self.sigma0_l = K * x_l / self.S_w

    # ---- Eqs. (3)-(6) --------------------------------------------------------------------
    def _tendon(self, theta, a0, xc, yc, xd, yd, wrapped):
        a = theta + a0
        xb, yb = self.r * math.cos(a), self.r * math.sin(a)
        if wrapped:
            xp, yp, fixed = xd, yd, math.hypot(xd - xc, yd - yc)
        else:
            xp, yp, fixed = xc, yc, 0.0
        pb = math.hypot(xb - xp, yb - yp)
        return fixed + pb, (xp * yb - yp * xb) / pb, abs(xb * yp - xp * yb) / pb

    def tendons(self, theta):
        p = self.p
        straight_u = self.r * math.sin(theta + self.a0u) >= p.a1_m
        pu, du, bu = self._tendon(theta, self.a0u, -p.a5_m, p.a1_m, p.a2_m, p.a1_m, not straight_u)
        pl, dl, bl = self._tendon(theta, self.a0l, -p.a4_m, -p.a1_m, p.a2_m, -p.a1_m, straight_u)
        return pu, du, bu, pl, dl, bl

    # ---- Eqs. (9)-(10) -------------------------------------------------------------------
    def g_heat(self, T, s):
        p = self.p
        A_S = p.A_S0_C + s / p.c_A_Pa_per_C
        if T <= A_S:
            return 1.0, 0.0, 0.0
        if T >= p.A_F0_C + s / p.c_A_Pa_per_C:
            return 0.0, 0.0, 0.0
        a = math.pi / (p.A_F0_C - p.A_S0_C)
        g = 0.5 * (math.cos(a * (T - A_S)) + 1.0)
        gT = -0.5 * a * math.sin(a * (T - A_S))
        return g, gT, -gT / p.c_A_Pa_per_C

    def g_cool(self, T, s):
        p = self.p
        M_F = p.M_F0_C + s / p.c_M_Pa_per_C
        if T >= p.M_S0_C + s / p.c_M_Pa_per_C:
            return 0.0, 0.0, 0.0
        if T <= M_F:
            return 1.0, 0.0, 0.0
        a = math.pi / (p.M_S0_C - p.M_F0_C)
        g = 0.5 * (math.cos(a * (T - M_F)) + 1.0)
        gT = -0.5 * a * math.sin(a * (T - M_F))
        return g, gT, -gT / p.c_M_Pa_per_C

    def xi(self, branch, start, held, T, s):
        if branch == HEATING:
            g, gT, gs = self.g_heat(T, s)
            xi, xT, xs = start * g, start * gT, start * gs
        elif branch == COOLING:
            g, gT, gs = self.g_cool(T, s)
            xi, xT, xs = start + (1 - start) * g, (1 - start) * gT, (1 - start) * gs
        else:
            return held, 0.0, 0.0
        if xi > 1.0:
            return 1.0, 0.0, 0.0
        if xi < 0.0:
            return 0.0, 0.0, 0.0
        return xi, xT, xs

    def branch_start(self, branch, xi, T, s):
        if branch == HEATING:
            g = self.g_heat(T, s)[0]
            return xi / g if g > 1e-12 else 1.0
        g = self.g_cool(T, s)[0]
        return (xi - g) / (1 - g) if g < 1 - 1e-12 else 0.0

    # ---- Eqs. (7)-(8): spring-slack tendon -----------------------------------------------
    def _k_spring(self, x, xlim):
        d = 1000.0 * (x - xlim)
        return self.p.spring_K_N_m if d <= 0 else self.p.spring_K_N_m + math.cosh(self.p.slack_penalty_per_mm * d) - 1

    def _f_spring(self, x, xlim):
        K, f = self.p.spring_K_N_m, self.p.slack_penalty_per_mm
        d = 1000.0 * (x - xlim)
        if x <= 0:
            return 0.0
        if d <= 0 or f == 0:
            return K * x
        return K * x + (math.sinh(f * d) - f * d) / (1000.0 * f)

    def spring_x(self, F, xlim):
        if F <= 0:
            return 0.0
        x = F / self.p.spring_K_N_m
        if x <= xlim:
            return x
        for _ in range(60):
            step = (self._f_spring(x, xlim) - F) / self._k_spring(x, xlim)
            x -= step
            if abs(step) < 1e-15:
                break
        return x

    def stress_rate(self, s, T, dT, branch, start, held, dpath, omega, xlim):
        p = self.p
        xi, xT, xs = self.xi(branch, start, held, T, s)
        D = p.D_A_Pa + xi * (p.D_M_Pa - p.D_A_Pa)
        K_s = self._k_spring(self.spring_x(s * self.S_w, xlim), xlim)
        K_D = D * self.S_w / self.L_w
        D_eq = K_s * K_D / (K_s + K_D) * self.L_w / self.S_w
        rate = D_eq * (dpath * omega / self.L_w - p.eps_R * xT * dT) / (1 + D_eq * p.eps_R * xs)
        return 0.0 if s <= 0 and rate < 0 else rate

    # ---- Eq. (11) --------------------------------------------------------------------------
    def dT(self, T, V, heating):
        p = self.p
        h0, h2 = ((p.h0_heating_W_m2K, p.h2_heating_W_m2K3) if heating
                  else (p.h0_cooling_W_m2K, p.h2_cooling_W_m2K3))
        loss = (h0 + h2 * T * T) * self.A_w * (T - p.T_amb_C)
        return (V * V / p.resistance_ohm_per_m - loss) / (self.M_w * p.specific_heat_J_kgK)

    # ---- Eqs. (1)-(2) --------------------------------------------------------------------
    def moment(self, y):
        theta, _, _, _, su, sl = y
        _, _, bu, _, _, bl = self.tendons(theta)
        p = self.p
        return su * self.S_w * bu - sl * self.S_w * bl - p.mass_kg * p.gravity_m_s2 * p.d_CM_m * math.cos(theta)

    def rhs(self, t, y, d):
        theta, omega, Tu, Tl, su, sl = y
        p = self.p
        _, du, bu, _, dl, bl = self.tendons(theta)
        dTu = self.dT(Tu, d["Vu"], d["heat_u"])
        dTl = self.dT(Tl, d["Vl"], d["heat_l"])
        dsu = self.stress_rate(su, Tu, dTu, *d["kin_u"], du, omega, self.xlim_u)
        dsl = self.stress_rate(sl, Tl, dTl, *d["kin_l"], dl, omega, self.xlim_l)
        M_E = su * self.S_w * bu - sl * self.S_w * bl - p.mass_kg * p.gravity_m_s2 * p.d_CM_m * math.cos(theta)
        if d["stuck"]:
            return [0.0, 0.0, dTu, dTl, dsu, dsl]
        fr = 0.0 if omega == 0 else math.copysign(p.M_DF_Nm + d["C_DF"] * abs(omega), omega)
        return [omega, (M_E - fr) / p.inertia_kg_m2, dTu, dTl, dsu, dsl]


# stick/slip events (Eq. 2), a hybrid automaton: stuck -> sliding when |M_E| rises through
# M_SF; sliding -> stuck (or creeping) when |omega| falls through omega_stick; creeping ->
# stuck when |M_E| falls through M_SF, -> sliding when |omega| rises through omega_stick.
def _breakaway(m, t, y, d):
    return abs(m.moment(y)) - m.p.M_SF_Nm


def _slow(m, t, y, d):
    return abs(y[1]) - m.p.stick_velocity_rad_s


def _fast(m, t, y, d):
    return abs(y[1]) - m.p.stick_velocity_rad_s


def _weak(m, t, y, d):
    return abs(m.moment(y)) - m.p.M_SF_Nm


for _f, _dir in ((_breakaway, 1), (_slow, -1), (_fast, 1), (_weak, -1)):
    _f.terminal, _f.direction = True, _dir


def _bind(f, m):
    g = partial(f, m)
    g.terminal, g.direction = f.terminal, f.direction
    return g


_EVENTS = {STUCK: [_breakaway], SLIDING: [_slow], CREEPING: [_weak, _fast]}


def parse_voltage(text: str) -> list[tuple[float, float, float]]:
    """``"T:V_UPPER:V_LOWER,..."`` -> [(t, V_upper, V_lower), ...] (as the engine's programs)."""
    return [tuple(float(x) for x in item.split(":")) for item in text.split(",") if item.strip()]


def simulate_baseline(params, voltage="0:8:0,6:0:0", t_end=20.0, method="RK45", rtol=1e-6, atol=None,
                      sample_s=0.01):
    """Integrate an open-loop voltage program; returns (t, theta_deg, info) on a ``sample_s`` grid.

    The integration restarts at every step of the program (a discontinuity of the RHS).
    ``info``: wall time [s], number of RHS evaluations, of solve_ivp calls and of events, and
    ``states`` (the six states on the grid).
    """
    steps = parse_voltage(voltage) if isinstance(voltage, str) else list(voltage)
    phases = [(ta, steps[i + 1][0] if i + 1 < len(steps) else t_end, vu, vl)
              for i, (ta, vu, vl) in enumerate(steps) if ta < t_end]
    m = Model(params)
    p = params
    if atol is None:  # per component: rad, rad/s, degC, degC, Pa, Pa
        atol = np.array([1e-9, 1e-7, 1e-6, 1e-6, 1.0, 1.0]) * (rtol / 1e-6)
    y = np.array([m.theta0, 0.0, p.T_init_C, p.T_init_C, m.sigma0_u, m.sigma0_l])
    grid = np.round(np.arange(0.0, t_end + 0.5 * sample_s, sample_s), 12)
    states = np.full((6, grid.size), np.nan)
    nfev = ncalls = nevents = 0
    mode = STUCK if abs(m.moment(y)) <= p.M_SF_Nm else SLIDING
    kin_u = (HOLD, p.xi_init, p.xi_init)  # (branch, start, held xi)
    kin_l = (HOLD, p.xi_init, p.xi_init)
    t0 = time.perf_counter()
    for (ta, tb, Vu, Vl) in phases:
        on_u, on_l = Vu > 0.0, Vl > 0.0
        # branch of each wire from the sign of dT/dt (continuous xi through the switch)
        for side in ("u", "l"):
            T = y[2] if side == "u" else y[3]
            s = y[4] if side == "u" else y[5]
            kin = kin_u if side == "u" else kin_l
            rate = m.dT(T, Vu, on_u) if side == "u" else m.dT(T, Vl, on_l)
            new = HEATING if rate > 0 else COOLING if rate < 0 else HOLD
            if new != kin[0]:
                xi_now = m.xi(*kin, T, s)[0]
                kin = (new, m.branch_start(new, xi_now, T, s), xi_now) if new != HOLD else (HOLD, kin[1], xi_now)
            if side == "u":
                kin_u = kin
            else:
                kin_l = kin
        t = ta
        while t < tb:
            d = {"Vu": Vu, "Vl": Vl, "heat_u": on_u, "heat_l": on_l, "kin_u": kin_u, "kin_l": kin_l,
                 "stuck": mode == STUCK, "C_DF": p.C_DF_heating_Nms if on_u or on_l else p.C_DF_cooling_Nms}
            events = _EVENTS[mode]
            sol = solve_ivp(m.rhs, (t, tb), y, method=method, rtol=rtol, atol=atol, args=(d,),
                            events=[_bind(f, m) for f in events], dense_output=True)
            nfev += sol.nfev
            ncalls += 1
            t_stop = sol.t[-1]
            sel = (grid >= t - 1e-12) & (grid <= t_stop + 1e-12)
            if sel.any():
                states[:, sel] = sol.sol(np.clip(grid[sel], t, t_stop))
            y = sol.y[:, -1].copy()
            t = t_stop
            if sol.status == 1:  # an event: the next stick/slip mode
                nevents += 1
                fired = next(f for f, te in zip(events, sol.t_events) if te.size)
                if fired is _breakaway:
                    mode = SLIDING
                elif fired is _fast:
                    mode = SLIDING
                elif fired is _weak or (fired is _slow and abs(m.moment(y)) <= p.M_SF_Nm):
                    mode = STUCK  # slow and |M_E| <= M_SF: Eq. (2) holds the joint
                    y[1] = 0.0
                else:
                    mode = CREEPING  # slow, but |M_E| > M_SF: watch both again
            else:
                t = tb
    wall = time.perf_counter() - t0
    info = {"wall_s": wall, "nfev": nfev, "calls": ncalls, "events": nevents,
            "states": states}  # theta, omega, T_upper, T_lower, sigma_upper, sigma_lower on the grid
    return grid, np.degrees(states[0]), info


if __name__ == "__main__":  # pragma: no cover
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from smafinger.parameters import get

    t, th, info = simulate_baseline(get("paper2010").replace(minor_loop_reversal_C=0.0))
    print(f"theta max {np.nanmax(th):.3f} deg at {t[np.nanargmax(th)]:.2f} s, final {th[-1]:.3f} deg; {info}")
