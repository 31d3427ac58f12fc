"""The equations of Gilardi et al. (2010), one module per block of Fig. 3.

=================  ==========================================  =====================
module             equations                                   symbolic (Table I)
=================  ==========================================  =====================
``dynamics``       (1a) (1b) joint dynamics, (2) friction       theta'' = f(theta, ...)
``kinematics``     (3)-(6) tendon path, strain, moment arm      eps = f(theta)
``constitutive``   (7)-(8) rate-form law, spring-slack tendon   sigma' = f(eps', T', xi')
``kinetics``       (9)-(10) cosine phase kinetics, minor loops  xi = f(sigma, T)
``heat``           (11) Joule heating and convection            T' = f(T, V)
``smafinger.control.pid``  (12) PWM-PID                         V = f(theta, ...)
=================  ==========================================  =====================

All functions here are numba-compiled and take plain floats in SI units (radians, metres,
pascals, degrees Celsius for temperatures as in the paper). Validation and unit conversion
happen only at the API edge (:mod:`smafinger.model.layout`).
"""
