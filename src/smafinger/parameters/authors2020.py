"""Parameters of the authors' public Simulink model (2020).

G. Gilardi, "FingerControl" (GitHub ``gabrielegilardi/FingerControl``, MIT licence, 2020),
``Initialization.m`` and function blocks, as listed in MODEL-NOTES ("Details of the
authors' 2020 model"). Differences from :mod:`.paper2010`: R_w = 8.66 Ohm/m,
M_SF = 0.011 N m, initial and ambient temperature 60 degC, spring lengths 17.44/15.48 mm
with the upper one solved from the friction-free static equilibrium, PID 8000/5000/30
evaluated at every step and 0 V in the cooling phase, error integral never reset, C_DF
switched by the enable flags, stress algebraic, friction holding only at the start.
"""

from .geometry import GEOMETRY
from .mechanisms import JointParameters
from .paper2010 import parameters as _paper

SOURCE = "Gilardi, FingerControl Simulink model (github.com/gabrielegilardi/FingerControl), 2020"


def parameters() -> JointParameters:
    # the model file's upper spring length, kept as its record: the equilibrium start below
    # solves the upper spring (a new length is refused under it, JointParameters.replace)
    recorded = _paper().replace(spring_init="given", spring_length_upper_m=17.44e-3)
    return recorded.replace(
        name="authors2020",
        source=SOURCE,
        resistance_ohm_per_m=8.66,
        M_SF_Nm=0.011,
        T_amb_C=60.0,
        T_init_C=60.0,
        spring_length_lower_m=15.48e-3,
        spring_init="equilibrium",
        K_P_per_rad=8000.0,
        K_V_s_per_rad=5000.0,
        K_I_per_rad_s=30.0,
        controller_update_s=0.0,
        controller_in_cooling=False,
        integral_reset="never",
        stress_law="algebraic",
        friction_sticking="initial-only",
        damping_switch="enabled",
        minor_loop_reversal_C=0.0,
        hysteresis="authors2020",
        **{k: v for k, v in GEOMETRY.items()},
    )
