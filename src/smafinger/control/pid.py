"""Eq. (12): PWM-PID controller.

    DC% = K_P Delta q + K_V Delta q' + K_I integral(Delta q) dt     (12a)
    t_DC = t_P DC% / 100                                            (12b)

Delta q = q_F(t) - q (theta_F - theta for the joint); DC% is clamped to [0, 100]. The wire sees
V_H for the first t_DC of every PWM period t_P and V_L for the rest (Fig. 6). With a
piecewise-constant target, Delta q' = -q' (the derivative acts on the measurement, so a new
target gives no derivative kick). A wire whose contraction lowers q uses the error with the
opposite sign (the paper's antagonist, -DC%).
"""

from ..jit import njit

#: the full duty [DC%]: the PID's output saturates here
FULL_DUTY = 100.0


@njit(cache=True, forceinline=True)
def pid_output(error, error_rate, error_integral, K_P, K_V, K_I):
    """Unclamped controller output DC% of Eq. (12a)."""
    return K_P * error + K_V * error_rate + K_I * error_integral


@njit(cache=True, forceinline=True)
def clamp_duty(u):
    """DC% clamped to [0, 100]."""
    return min(max(u, 0.0), 100.0)


@njit(cache=True, forceinline=True)
def saturated_against(u, error, limit):
    """Anti-windup (conditional integration): the output is at its limit (``|u| >= limit``, DC%)
    and the error pushes it further."""
    return (u >= limit and error > 0.0) or (u <= -limit and error < 0.0)


@njit(cache=True, forceinline=True)
def on_time(duty_percent, t_P):
    """t_DC = t_P DC% / 100 of Eq. (12b) (in the unit of t_P)."""
    return duty_percent / 100.0 * t_P


@njit(cache=True, forceinline=True)
def pwm_edge(period_start, duty_percent, t_P):
    """The falling edge of a PWM period (Eq. 12b), or -1 when the duty is 0 or 100 % (no edge)."""
    if 0.0 < duty_percent < 100.0:
        return period_start + on_time(duty_percent, t_P)
    return -1.0


@njit(cache=True, forceinline=True)
def pwm_output(level, low, duty_percent, on, t_in_period):
    """The drive at time ``t_in_period`` into the PWM period (Fig. 6): ``level`` while on, ``low`` after."""
    if duty_percent >= 100.0 or (duty_percent > 0.0 and t_in_period < on):
        return level
    return low
