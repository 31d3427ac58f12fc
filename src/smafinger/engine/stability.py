"""Where each fixed-step integrator is stable (numba-free: the checks before a run read it).

Two kinds of mode bound a step:

- a real, negative one, the viscous damping (-C_DF/I of Eq. 2 on the joint, -c/m on a slider):
  :data:`REAL_AXIS`, the largest |lambda h| of the method's stability region on the negative
  real axis (:func:`smafinger.plausibility.blowup_hint` names it after a blow-up);
- a barely damped oscillation, the wire against a slider's mass (omega, with damping c over the
  mass): :data:`UNDAMPED`, the largest h omega RK4 holds on the imaginary axis. Euler and
  exponential Euler (explicit in the wire's stiffness) hold none: they amplify such a mode at
  every step unless h omega^2 < c (:func:`smafinger.engine.numerics.unstable_step`).
  ``semi-implicit`` takes the stiffness implicitly and holds any step.
"""

#: |lambda h| up to which each explicit integrator is stable on a real, negative mode: Euler 2,
#: classical RK4 2.785 (its stability region on the negative real axis; the authors' solver is RK4)
REAL_AXIS = {"euler": 2.0, "rk4": 2.785, "authors-ode4": 2.785}
#: h omega up to which each integrator holds an undamped mode: RK4 2 sqrt(2) (its region on the
#: imaginary axis); 0 for the ones that amplify it unless the damping outweighs h omega^2
UNDAMPED = {"rk4": 2.0 * 2.0 ** 0.5, "authors-ode4": 2.0 * 2.0 ** 0.5, "euler": 0.0, "exponential": 0.0}
