"""The equations of Gilardi et al. (2010), one module per block of Fig. 3, for any mechanism.

==================  ===========================================  ========================
module              equations                                    symbolic (Table I)
==================  ===========================================  ========================
``dynamics``        (1a) (1b) dynamics and load, (2) friction     q'' = f(q, q', sigma)
``kinematics``      (3)-(6) tendon path, strain, moment arm       eps = f(q)
``constitutive``    (7)-(8) rate-form law, spring-slack tendon    sigma' = f(eps', T', xi')
``kinetics``        (9)-(10) cosine phase kinetics, minor loops   xi = f(sigma, T)
``heat``            (11) Joule heating and convection             T' = f(T, V)
``wire``            (6)-(11) together, for one wire
``smafinger.control``  (12) PWM-PID, Sec. 2.6 strategies          V = f(q, ...)
==================  ===========================================  ========================

The compiled functions take plain floats and named records (:mod:`.records`) in SI units
(radians, metres, pascals; degrees Celsius for temperatures, as in the paper). Validation and
unit conversion happen only at the API edge (:mod:`.build`).
"""
