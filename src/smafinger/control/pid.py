"""Eq. (12): PWM-PID controller.

    DC% = K_P Delta theta + K_V Delta theta' + K_I integral(Delta theta) dt     (12a)
    t_DC = t_P DC% / 100                                                       (12b)

Delta theta = theta_F(t) - theta; DC% is clamped to [0, 100]. The wire sees V_H for the
first t_DC of every PWM period t_P and V_L for the rest. With a piecewise-constant target,
Delta theta' = -theta' (the derivative acts on the measurement, so a new target gives no
derivative kick). The antagonist uses the error with the opposite sign, i.e. -DC%.
"""

from numba import njit


@njit(cache=True)
def pid_output(error, error_rate, error_integral, K_P, K_V, K_I):
    """Unclamped controller output DC% of Eq. (12a)."""
    return K_P * error + K_V * error_rate + K_I * error_integral


@njit(cache=True)
def clamp_duty(u):
    """DC% clamped to [0, 100]."""
    if u < 0.0:
        return 0.0
    if u > 100.0:
        return 100.0
    return u


def on_time(duty_percent, t_P):
    """t_DC = t_P DC% / 100 of Eq. (12b) [s]."""
    return t_P * duty_percent / 100.0
