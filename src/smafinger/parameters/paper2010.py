"""Parameters of Gilardi, Haslam, Bundhoo & Park (2010).

G. Gilardi, E. Haslam, V. Bundhoo, E. J. Park, "A shape memory alloy based tendon-driven
actuation system for biomimetic artificial fingers, part II: modelling and control",
Robotica 28(5):675-687, 2010.

Values from Table II, with the heat-convection and friction coefficients replaced by the
values identified in Sec. 3.2 (heating: h0 = 20, h2 = 5e-4, C_DF = 0.03; cooling: h0 = 41,
h2 = 5e-4, C_DF = 0.09) and the PID gains of Sec. 4 (3000, 3000, 50, updated every 0.01 s).
Table II's R_w "Ohm m" is read as Ohm/m and c_M "Pa" as Pa/degC (MODEL-NOTES).
The joint geometry is the authors' (see :mod:`.geometry`).

Friction follows Sec. 3.1: "any stick-slip effects were neglected ... the friction is purely
viscous after the onset of the motion", i.e. ``friction_sticking = "initial-only"`` (the joint is
held by M_SF only until it first moves). smafinger 0.1 used ``"restick"`` here, with which a
-40 -> -30 -> -40 deg run sticks for good at -30.00 deg (the spring moment there is below M_SF);
that rule stays available as an option.

Choices of ours where the paper is silent (named options of the model):
``spring_init = "equilibrium"`` (upper spring solved from the moment balance, MODEL-NOTES),
``damping_switch = "heating-phase"`` (C_DF's heating value while a wire is in its controller's
heating phase), ``integral_reset = "segment"``, ``controller_in_cooling = True`` (Fig. 11 case i),
``joule_heating = "per-metre"`` (Eq. 11 read literally, MODEL-NOTES),
``hysteresis = "memory"`` (return-point memory, docs/hysteresis.md; smafinger 0.1's rule is
``"deadband"`` with ``minor_loop_reversal_C = 0.5``).

:func:`table2` gives the set with Table II's own h0 = 70, h2 = 0.001, C_DF = 0.02 for both
phases, as used in the parametric analysis of Sec. 3.1 (Figs. 7-8).
"""

from .geometry import GEOMETRY
from .mechanisms import JointParameters
from .options import (
    AntiWindup, DampingSwitch, FrictionSticking, Hysteresis, IntegralReset, JouleHeating, ModelOptions, SpringInit,
    StressLaw, ThermalModel,
)

SOURCE = "Gilardi et al., Robotica 28(5):675-687, 2010, Table II and Sec. 3.2"


#: the paper's model options (and our choices where it is silent, see above)
OPTIONS = ModelOptions(
    spring_init=SpringInit.EQUILIBRIUM,
    stress_law=StressLaw.RATE,
    friction_sticking=FrictionSticking.INITIAL_ONLY,
    damping_switch=DampingSwitch.HEATING_PHASE,
    integral_reset=IntegralReset.SEGMENT,
    anti_windup=AntiWindup.NONE,
    controller_in_cooling=True,
    joule_heating=JouleHeating.PER_METRE,
    hysteresis=Hysteresis.MEMORY,
    thermal_model=ThermalModel.SINGLE_NODE,
)


def parameters() -> JointParameters:
    return JointParameters(
        name="paper2010",
        source=SOURCE,
        wire_density_kg_m3=6450.0,
        wire_diameter_m=0.375e-3,
        wire_length_m=0.385,
        specific_heat_J_kgK=322.0,
        resistance_ohm_per_m=8.6,
        A_S0_C=75.0,
        A_F0_C=110.0,
        M_S0_C=85.0,
        M_F0_C=60.0,
        c_A_Pa_per_C=10.3e6,
        c_M_Pa_per_C=10.3e6,
        D_A_Pa=75e9,
        D_M_Pa=28e9,
        eps_R=0.023,
        xi_init=1.0,
        minor_loop_reversal_C=0.5,
        T_amb_C=23.0,
        T_init_C=23.0,
        h0_heating_W_m2K=20.0,
        h2_heating_W_m2K3=5e-4,
        h0_cooling_W_m2K=41.0,
        h2_cooling_W_m2K3=5e-4,
        inertia_kg_m2=4.88e-5,
        mass_kg=1.5e-2,
        d_CM_m=0.035,
        gravity_m_s2=9.81,
        M_SF_Nm=0.01,
        M_DF_Nm=0.0,
        C_DF_heating_Nms=0.03,
        C_DF_cooling_Nms=0.09,
        stick_velocity_rad_s=1e-3,
        theta0_deg=-40.0,
        spring_length_upper_m=17.4e-3,
        spring_length_lower_m=15.5e-3,
        V_H_V=8.0,
        V_L_V=0.0,
        pwm_period_s=1e-3,
        K_P_per_rad=3000.0,
        K_V_s_per_rad=3000.0,
        K_I_per_rad_s=50.0,
        controller_update_s=0.01,
        options=OPTIONS,
        **GEOMETRY,
    )


def table2() -> JointParameters:
    """Table II as printed: h0 = 70, h2 = 0.001, C_DF = 0.02 in both phases (Sec. 3.1)."""
    return parameters().replace(
        name="paper2010-table2",
        source=SOURCE.replace("and Sec. 3.2", "(Sec. 3.1 parametric analysis)"),
        h0_heating_W_m2K=70.0,
        h2_heating_W_m2K3=1e-3,
        h0_cooling_W_m2K=70.0,
        h2_cooling_W_m2K3=1e-3,
        C_DF_heating_Nms=0.02,
        C_DF_cooling_Nms=0.02,
    )
