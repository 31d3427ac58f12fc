"""Eqs. (1)-(2): joint dynamics with gravity and stick/slip friction.

    I theta'' = M_E - M_Fr                                                  (1a)
    M_E = F_U b_U - F_L b_L - m g d_CM cos(theta),   F = sigma S_w          (1b)
    M_Fr = sign(theta')(M_DF + C_DF |theta'|)   if |M_E| > M_SF             (2)
    M_Fr = M_E                                  if |M_E| <= M_SF (stuck)

Sticking is a discrete state decided at step boundaries by the engine: the joint is held
(theta' = theta'' = 0) while stuck; it breaks away when |M_E| > M_SF.
"""

from numba import njit


@njit(cache=True)
def external_moment(sigma_u, sigma_l, arm_u, arm_l, theta_cos, S_w, m, g, d_CM):
    """M_E [N m] of Eq. (1b); ``theta_cos`` = cos(theta)."""
    return sigma_u * S_w * arm_u - sigma_l * S_w * arm_l - m * g * d_CM * theta_cos


@njit(cache=True)
def sliding_friction(omega, M_DF, C_DF):
    """M_Fr [N m] of Eq. (2) while sliding."""
    if omega > 0.0:
        return M_DF + C_DF * omega
    if omega < 0.0:
        return -(M_DF - C_DF * omega)
    return 0.0


@njit(cache=True)
def angular_acceleration(M_E, omega, stuck, I, M_DF, C_DF):
    """theta'' [rad/s^2] of Eq. (1a)."""
    if stuck:
        return 0.0
    return (M_E - sliding_friction(omega, M_DF, C_DF)) / I
