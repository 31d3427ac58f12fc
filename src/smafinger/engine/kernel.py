"""The compiled fixed-step simulation loop.

Time runs on an integer clock of ``tick_s`` seconds (1 ns): step ends, PWM period starts,
controller updates, output samples and target changes fall on exact integer ticks, so no
time drifts from adding dt. Within a step, the PWM duty edges (period start + t_DC, Eq. 12b)
split the step so that each sub-step sees a constant voltage: the edges are resolved
exactly whatever the step size.

At every sub-step start the discrete state is updated: voltages, kinetics branch (sign of
dT/dt, with the minor-loop start value re-solved on a reversal), stick/slip, and the
interlock is checked (both wires driven at once counts as a violation).
"""

import math

import numpy as np
from numba import njit
from numba.np.unsafe.ndarray import to_fixed_tuple

from ..control.pid import pid_output
from ..control.strategies import (
    AUTO, BOTH, COOPERATIVE, INDEPENDENT, LOWER, NONE, OPEN_LOOP, RELEASE_XI, UPPER,
    actuator_commands, independent_agonist,
)
from ..model.kinetics import HOLD, branch_start, next_branch
from ..model.layout import (
    P_A_F0, P_A_S0, P_C_DF_c, P_C_DF_h, P_K_I, P_K_P, P_K_V, P_L_w, P_M_F0, P_M_S0, P_M_SF,
    P_T_init, P_V_H, P_V_L, P_c_A, P_c_M, P_damping_enabled, P_eps_tot0_l, P_eps_tot0_u,
    P_anti_windup, P_integral_never, P_keep_on_cooling, P_omega_stick, P_path0_l, P_path0_u, P_sigma0_l,
    P_sigma0_u, P_reversal, P_stick_initial_only, P_stress_algebraic, P_theta0, P_xi_init, P_xlim_l,
    P_xlim_u,
)
from ..model.kinematics import both_tendons
from ..model.layout import N_PARAMS, P_a0_l, P_a0_u, P_a1, P_a2, P_a4, P_a5, P_r
from .rhs import (
    A_BL, A_BU, A_ME, A_SL, A_SU, A_XIL, A_XIU, A_XL, A_XU, D_BRL, D_BRU, D_CDF, D_HEATL,
    D_HEATU, D_INTON, D_STL, D_STU, D_STUCK, D_THF, D_VL, D_VU, D_XHL, D_XHU, N_DISC, N_STATE,
    Y_EL, Y_EU, Y_INT, Y_OMEGA, Y_SL, Y_SU, Y_THETA, Y_TL, Y_TU, _xi, algebraic_stress,
    _kin_at, evaluate, integrate_rest, kinematics, wire_temperature_rate,
)

# output columns
OUT_COLUMNS = (
    "t", "theta", "theta_ref", "omega", "T_u", "T_l", "xi_u", "xi_l", "sigma_u", "sigma_l",
    "arm_u", "arm_l", "spring_u", "spring_l", "V_u", "V_l", "duty_u", "duty_l", "E_u", "E_l",
    "segment", "enabled_u", "enabled_l", "stuck", "heating_u", "heating_l",
)
N_OUT = len(OUT_COLUMNS)

# counters
C_STATUS, C_SUBSTEPS, C_VIOLATIONS, C_EVALS, C_STICKS = range(5)
N_COUNTERS = 5
STATUS_OK = 0
STATUS_BLOWUP = 1


@njit(cache=True)
def _wire_xi_sigma(theta, T, s, br, st, xh, p, upper):
    """xi and sigma of one wire (temperature T, stress state s) at angle theta on branch br.

    Computed only where needed (a branch change, the independent strategy's release test):
    a pure function of its arguments, so the same bits whenever it is evaluated.
    """
    if p[P_stress_algebraic] != 0.0:
        pu, _, _, pl, _, _ = both_tendons(theta, p[P_r], p[P_a0_u], p[P_a0_l], p[P_a1],
                                          p[P_a2], p[P_a4], p[P_a5])
        if upper:
            eps = p[P_eps_tot0_u] + (pu - p[P_path0_u]) / p[P_L_w]
            s, xi, _ = algebraic_stress(eps, T, br, st, xh, p, p[P_xlim_u])
        else:
            eps = p[P_eps_tot0_l] + (pl - p[P_path0_l]) / p[P_L_w]
            s, xi, _ = algebraic_stress(eps, T, br, st, xh, p, p[P_xlim_l])
        return xi, s
    return _xi(br, st, xh, T, s, p)[0], s


@njit(cache=True)
def _wire_xi(y, d, p, upper):
    """xi of one wire at state y on the branch held in d (tuples, as in evaluate)."""
    if upper:
        return _wire_xi_sigma(y[Y_THETA], y[Y_TU], y[Y_SU], d[D_BRU], d[D_STU], d[D_XHU], p,
                              True)[0]
    return _wire_xi_sigma(y[Y_THETA], y[Y_TL], y[Y_SL], d[D_BRL], d[D_STL], d[D_XHL], p,
                          False)[0]


@njit(cache=True, inline="always")
def _update_branch(br, st, xh, dT, theta, T, s, p, turn, upper):
    """Select the kinetics branch; re-solve the start value on a change (minor loops).

    xi and sigma at the reversal are those of the state (theta, T, s) on the old branch.
    Returns the new (branch, start value, held xi, turning temperature).
    """
    nb, turn = next_branch(int(br), dT, T, turn, p[P_reversal])
    if nb != int(br):
        xi_now, sigma = _wire_xi_sigma(theta, T, s, br, st, xh, p, upper)
        if nb == HOLD:
            xh = xi_now
        else:
            st = branch_start(nb, xi_now, T, sigma, p[P_A_S0], p[P_A_F0], p[P_c_A],
                              p[P_M_S0], p[P_M_F0], p[P_c_M])
        br = float(nb)
    return br, st, xh, turn


@njit(cache=True, nogil=True)
def run_kernel(p, seg_start, seg_target, seg_enable, strategy, wait_release,
               volt_ticks, volt_u, volt_l, method, dt_ticks, tick_s, t_end_ticks,
               out_ticks, update_ticks, pwm_ticks, tol_rad, hold_ticks,
               out, seg_actual, seg_reached, counters, err_state):
    """Simulate from t = 0 to t_end; fill ``out`` (one row per output sample).

    ``seg_reached[k]`` is the tick at which segment k's target was entered for good (within
    ``tol_rad`` for ``hold_ticks``), -1 if never. Returns nothing; ``counters[C_STATUS]`` is STATUS_BLOWUP (with time and state in
    ``err_state``) if the state became NaN or Inf.
    """
    y = np.zeros(N_STATE)
    y[Y_THETA] = p[P_theta0]
    y[Y_TU] = p[P_T_init]
    y[Y_TL] = p[P_T_init]
    y[Y_SU] = p[P_sigma0_u]
    y[Y_SL] = p[P_sigma0_l]
    d = np.zeros(N_DISC)
    d[D_BRU] = HOLD
    d[D_BRL] = HOLD
    d[D_XHU] = p[P_xi_init]
    d[D_XHL] = p[P_xi_init]
    d[D_STU] = p[P_xi_init]
    d[D_STL] = p[P_xi_init]
    d[D_INTON] = 1.0
    turn_u = p[P_T_init]
    turn_l = p[P_T_init]
    # the hot path works on tuples of floats (parameters, state, discrete inputs): passed by
    # value, they need no reference counting, unlike arrays
    pt = to_fixed_tuple(p, N_PARAMS)
    kin_theta = y[Y_THETA]
    kin = kinematics(kin_theta, pt)
    bounds = np.empty(3)

    nseg = seg_start.shape[0]
    nvolt = volt_ticks.shape[0]
    keep_on = p[P_keep_on_cooling] != 0.0
    V_L = p[P_V_L]
    # controller / actuator state
    en_u = False
    en_l = False
    heat_u = False
    heat_l = False
    duty_u = 0.0
    duty_l = 0.0
    level_u = p[P_V_H]
    level_l = p[P_V_H]
    agonist = NONE
    waiting = False
    wait_side = NONE
    pending = NONE
    theta_F = p[P_theta0]
    next_seg = 0
    vi = 0
    band_since = -1
    confirmed = False
    stuck = False
    omega_prev = 0.0
    initial_only = p[P_stick_initial_only] != 0.0

    t = 0
    next_out = 0
    out_i = 0
    n_out = out.shape[0]
    first = True
    while True:
        force_update = False
        # ---- target schedule -------------------------------------------------------
        while next_seg < nseg:
            s = seg_start[next_seg]
            if (s >= 0 and s <= t) or (s < 0 and confirmed):
                k = next_seg
                theta_F = seg_target[k]
                seg_actual[k] = t
                if p[P_integral_never] == 0.0:
                    y[Y_INT] = 0.0
                en = seg_enable[k]
                waiting = False
                if strategy == OPEN_LOOP:
                    pass
                elif en == AUTO and strategy == COOPERATIVE:
                    en_u = True
                    en_l = True
                elif en == AUTO and strategy == INDEPENDENT:
                    ag = independent_agonist(theta_F, y[Y_THETA], agonist)
                    if (wait_release and agonist != NONE and ag != agonist
                            and _wire_xi(to_fixed_tuple(y, N_STATE), to_fixed_tuple(d, N_DISC), pt,
                                         agonist == UPPER) < RELEASE_XI):
                        waiting = True
                        wait_side = agonist
                        pending = ag
                        en_u = False
                        en_l = False
                    else:
                        en_u = ag == UPPER
                        en_l = ag == LOWER
                    agonist = ag
                else:
                    en_u = en == UPPER or en == BOTH
                    en_l = en == LOWER or en == BOTH
                band_since = -1
                confirmed = False
                force_update = True
                next_seg += 1
            else:
                break
        if waiting:
            w_xi = _wire_xi(to_fixed_tuple(y, N_STATE), to_fixed_tuple(d, N_DISC), pt,
                            wait_side == UPPER)
            if w_xi >= RELEASE_XI:
                waiting = False
                en_u = pending == UPPER
                en_l = pending == LOWER
                force_update = True
                if p[P_integral_never] == 0.0:
                    y[Y_INT] = 0.0
        # ---- controller ------------------------------------------------------------
        if strategy == OPEN_LOOP:
            while vi < nvolt and volt_ticks[vi] <= t:
                level_u = volt_u[vi]
                level_l = volt_l[vi]
                vi += 1
            en_u = level_u > 0.0
            en_l = level_l > 0.0
            heat_u = en_u
            heat_l = en_l
            duty_u = 100.0 if en_u else 0.0
            duty_l = 100.0 if en_l else 0.0
        elif force_update or update_ticks == 0 or t % update_ticks == 0:
            e = theta_F - y[Y_THETA]
            u = pid_output(e, -y[Y_OMEGA], y[Y_INT], p[P_K_P], p[P_K_V], p[P_K_I])
            duty_u, duty_l, heat_u, heat_l = actuator_commands(u, en_u, en_l, theta_F,
                                                               y[Y_THETA], keep_on)
            # conditional integration: freeze the integral while saturated the same way
            d[D_INTON] = 1.0
            if p[P_anti_windup] != 0.0 and ((u >= 100.0 and e > 0.0) or (u <= -100.0 and e < 0.0)):
                d[D_INTON] = 0.0
        if p[P_damping_enabled] != 0.0:
            damp_heat = en_u or en_l
        else:
            damp_heat = heat_u or heat_l
        d[D_CDF] = p[P_C_DF_h] if damp_heat else p[P_C_DF_c]
        d[D_THF] = theta_F
        d[D_HEATU] = 1.0 if heat_u else 0.0
        d[D_HEATL] = 1.0 if heat_l else 0.0

        # ---- interval [t, t_next] -----------------------------------------------
        ps = (t // pwm_ticks) * pwm_ticks
        t_next = min(((t // dt_ticks) + 1) * dt_ticks, t_end_ticks)
        if (0.0 < duty_u < 100.0) or (0.0 < duty_l < 100.0):
            # a duty strictly inside (0, 100) %: split at every PWM period start
            t_next = min(t_next, ps + pwm_ticks)
        t_next = min(t_next, ((t // out_ticks) + 1) * out_ticks)
        if update_ticks > 0:
            t_next = min(t_next, ((t // update_ticks) + 1) * update_ticks)
        if next_seg < nseg and seg_start[next_seg] > t:
            t_next = min(t_next, seg_start[next_seg])
        if strategy == OPEN_LOOP and vi < nvolt:
            t_next = min(t_next, volt_ticks[vi])
        on_u = duty_u / 100.0 * pwm_ticks
        on_l = duty_l / 100.0 * pwm_ticks
        # duty edges exist only for a duty strictly inside (0, 100) %
        e1 = ps + on_u if 0.0 < duty_u < 100.0 else -1.0
        e2 = ps + on_l if 0.0 < duty_l < 100.0 else -1.0
        if e1 > e2:
            e1, e2 = e2, e1
        nb = 0
        if e1 > t and e1 < t_next:
            bounds[nb] = e1
            nb += 1
        if e2 > t and e2 < t_next and (nb == 0 or e2 > bounds[nb - 1]):
            bounds[nb] = e2
            nb += 1
        bounds[nb] = t_next
        nb += 1

        a = float(t)
        for j in range(nb):
            b = bounds[j]
            mid = 0.5 * (a + b) - ps
            Vu = level_u if (duty_u >= 100.0 or (duty_u > 0.0 and mid < on_u)) else V_L
            Vl = level_l if (duty_l >= 100.0 or (duty_l > 0.0 and mid < on_l)) else V_L
            d[D_VU] = Vu
            d[D_VL] = Vl
            if Vu > V_L and Vl > V_L and b > a:
                counters[C_VIOLATIONS] += 1
            dTu = wire_temperature_rate(y[Y_TU], Vu, heat_u, pt)
            dTl = wire_temperature_rate(y[Y_TL], Vl, heat_l, pt)
            d[D_BRU], d[D_STU], d[D_XHU], turn_u = _update_branch(
                d[D_BRU], d[D_STU], d[D_XHU], dTu, y[Y_THETA], y[Y_TU], y[Y_SU], pt, turn_u, True)
            d[D_BRL], d[D_STL], d[D_XHL], turn_l = _update_branch(
                d[D_BRL], d[D_STL], d[D_XHL], dTl, y[Y_THETA], y[Y_TL], y[Y_SL], pt, turn_l, False)
            d[D_STUCK] = 1.0 if stuck else 0.0
            yt = to_fixed_tuple(y, N_STATE)
            dv = to_fixed_tuple(d, N_DISC)
            kin = _kin_at(yt[Y_THETA], kin_theta, kin, pt)
            kin_theta = yt[Y_THETA]
            k1, aux = evaluate(yt, dv, pt, kin)
            counters[C_EVALS] += 1
            # ---- stick / slip (Eq. 2) ------------------------------------------------
            me = abs(aux[A_ME])
            new_stuck = stuck
            if first:
                new_stuck = me <= p[P_M_SF] and y[Y_OMEGA] == 0.0
                first = False
            elif stuck:
                if me > p[P_M_SF]:
                    new_stuck = False
            elif not initial_only:
                om = y[Y_OMEGA]
                if me <= p[P_M_SF] and (abs(om) <= p[P_omega_stick] or om * omega_prev < 0.0):
                    new_stuck = True
            if new_stuck != stuck:
                if new_stuck:
                    y[Y_OMEGA] = 0.0
                    counters[C_STICKS] += 1
                stuck = new_stuck
                d[D_STUCK] = 1.0 if stuck else 0.0
                yt = to_fixed_tuple(y, N_STATE)
                dv = to_fixed_tuple(d, N_DISC)
                k1, aux = evaluate(yt, dv, pt, kin)
                counters[C_EVALS] += 1
            omega_prev = y[Y_OMEGA]
            # ---- output sample at t -----------------------------------------------------
            if j == 0 and t == next_out and out_i < n_out:
                out[out_i, 0] = t * tick_s
                out[out_i, 1] = y[Y_THETA]
                out[out_i, 2] = theta_F
                out[out_i, 3] = y[Y_OMEGA]
                out[out_i, 4] = y[Y_TU]
                out[out_i, 5] = y[Y_TL]
                out[out_i, 6] = aux[A_XIU]
                out[out_i, 7] = aux[A_XIL]
                out[out_i, 8] = aux[A_SU]
                out[out_i, 9] = aux[A_SL]
                out[out_i, 10] = aux[A_BU]
                out[out_i, 11] = aux[A_BL]
                out[out_i, 12] = aux[A_XU]
                out[out_i, 13] = aux[A_XL]
                out[out_i, 14] = Vu
                out[out_i, 15] = Vl
                out[out_i, 16] = duty_u
                out[out_i, 17] = duty_l
                out[out_i, 18] = y[Y_EU]
                out[out_i, 19] = y[Y_EL]
                out[out_i, 20] = next_seg - 1
                out[out_i, 21] = 1.0 if en_u else 0.0
                out[out_i, 22] = 1.0 if en_l else 0.0
                out[out_i, 23] = 1.0 if stuck else 0.0
                out[out_i, 24] = 1.0 if heat_u else 0.0
                out[out_i, 25] = 1.0 if heat_l else 0.0
                out_i += 1
                next_out += out_ticks
            if b > a:
                yt = integrate_rest(method, yt, (b - a) * tick_s, dv, pt, k1, kin)
                for i in range(N_STATE):
                    y[i] = yt[i]
                counters[C_EVALS] += 3 if method == 1 else 0
                counters[C_SUBSTEPS] += 1
            if p[P_stress_algebraic] == 0.0:
                if y[Y_SU] < 0.0:
                    y[Y_SU] = 0.0
                if y[Y_SL] < 0.0:
                    y[Y_SL] = 0.0
            if stuck:
                y[Y_OMEGA] = 0.0
            for i in range(N_STATE):
                if not math.isfinite(y[i]):
                    counters[C_STATUS] = 1
                    err_state[0] = b * tick_s
                    for q in range(N_STATE):
                        err_state[1 + q] = y[q]
                    return
            a = b
        if t >= t_end_ticks:
            break
        t = t_next
        # ---- reach tracking (for targets issued on reach) ----------------------------
        if abs(y[Y_THETA] - theta_F) <= tol_rad:
            if band_since < 0:
                band_since = t
            if t - band_since >= hold_ticks and not confirmed:
                confirmed = True
                if next_seg >= 1:
                    seg_reached[next_seg - 1] = band_since
        else:
            band_since = -1
        if t >= t_end_ticks:
            # record the final sample and stop
            if t == next_out and out_i < n_out:
                continue
            break
    return
