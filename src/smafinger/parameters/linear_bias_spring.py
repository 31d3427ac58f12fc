"""A typical bench rig: a 0.5 mm, 1 m NiTi wire pulling a 20 g slider against a bias spring.

A template to start from, not a fit to any one rig: edit it (``smafinger params
linear-bias-spring --out rig.toml``) or fit it to your recordings. Sources:

- Wire (density, specific heat, resistivity 76-82 micro-ohm cm, so R_w = 4.1 ohm/m at 0.5 mm,
  moduli 83/28 GPa, transformation temperatures of the 70 degC alloy: A_s 68, A_f 78, M_s 52,
  M_f 42 degC): Dynalloy, Inc., *Technical Characteristics of Flexinol Actuator Wires*.
- Stress-temperature slopes c_A = c_M = 10.3 MPa/degC: Gilardi et al. (2010), Table II.
- Recoverable strain 1.7 %: chosen so that the stroke is about 17 mm at this load, as on the
  bench rig of issue 12 (Dynalloy recommends at most 3-5 % for long life).
- Convection h = 40 + 0.001 T^2 W/(m^2 K): natural convection around a 0.5 mm horizontal wire
  in still air (Churchill-Chu correlation, Rayleigh number about 0.5: Nu about 0.8, h about
  40 W/(m^2 K)), with the paper's quadratic term for the rise with temperature; the wire is in
  open air, so heating and cooling share it. Time constant M_w C_p / (h A_w) = 6.5 s.
- Bias spring 60 N/m with an 8 N preload (wire stress 41 MPa at the start), 20 g slider: the
  usual range of such rigs (40-80 N/m, 10-50 g).
- Drive: a 12 V supply switched at 1 kHz (full on: 2.9 A, 35 W, through the R_w that Eq. (11)
  heats with); the controller runs at 100 Hz.
- Not matched to R_w: the resistance as sensed (``model.resistance``, the ``resistivity_*``
  fields) keeps the MAS model's resistivities (89 / 102 micro-ohm cm), so the ``R_wire_ohm``
  column reads 4.6-5.4 ohm where the heating uses 4.1 ohm. Self-sensing reads the resistance
  relative to its value at rest, so only that column's level is off; set the ``resistivity_*``
  fields to your wire's measured values.
  PID gains: a starting point (1 mm of error gives 30 % duty; it reaches 10 mm and then 4 mm
  within 0.5 mm), to be tuned.

Model options: the algebraic stress law (so the static positions follow from the force balance
of wire and spring), Joule heating of the whole wire (``whole-wire``: electrical power
V^2 / (R_w L_w) spread over the wire; Eq. 11's per-metre reading is the paper's, see
MODEL-NOTES), integral anti-windup on.
"""

from .mechanisms import LinearActuatorParameters
from .options import (
    AntiWindup, DampingSwitch, FrictionSticking, Hysteresis, IntegralReset, JouleHeating, ModelOptions, SpringInit,
    StressLaw, ThermalModel,
)

SOURCE = ("Template bench rig: Dynalloy Flexinol 0.5 mm wire data; Gilardi et al. 2010 Table II (c_A, c_M); "
          "natural convection (Churchill-Chu); see smafinger.parameters.linear_bias_spring")

OPTIONS = ModelOptions(
    spring_init=SpringInit.GIVEN,
    stress_law=StressLaw.ALGEBRAIC,
    friction_sticking=FrictionSticking.RESTICK,
    damping_switch=DampingSwitch.HEATING_PHASE,
    integral_reset=IntegralReset.SEGMENT,
    anti_windup=AntiWindup.CLAMP,
    controller_in_cooling=True,
    joule_heating=JouleHeating.WHOLE_WIRE,
    hysteresis=Hysteresis.MEMORY,
    thermal_model=ThermalModel.SINGLE_NODE,
)


def parameters() -> LinearActuatorParameters:
    return LinearActuatorParameters(
        name="linear-bias-spring",
        source=SOURCE,
        wire_density_kg_m3=6450.0,
        wire_diameter_m=0.5e-3,
        wire_length_m=1.0,
        specific_heat_J_kgK=322.0,
        resistance_ohm_per_m=4.1,
        A_S0_C=68.0,
        A_F0_C=78.0,
        M_S0_C=52.0,
        M_F0_C=42.0,
        c_A_Pa_per_C=10.3e6,
        c_M_Pa_per_C=10.3e6,
        D_A_Pa=83e9,
        D_M_Pa=28e9,
        eps_R=0.017,
        xi_init=1.0,
        minor_loop_reversal_C=0.5,
        T_amb_C=23.0,
        T_init_C=23.0,
        h0_heating_W_m2K=40.0,
        h2_heating_W_m2K3=1e-3,
        h0_cooling_W_m2K=40.0,
        h2_cooling_W_m2K3=1e-3,
        V_H_V=12.0,
        V_L_V=0.0,
        pwm_period_s=1e-3,
        controller_update_s=0.01,
        slider_mass_kg=0.02,
        viscous_damping_N_s_m=0.5,
        static_friction_N=0.0,
        coulomb_friction_N=0.0,
        stick_velocity_m_s=1e-4,
        bias_spring_K_N_m=60.0,
        bias_spring_preload_N=8.0,
        external_force_N=0.0,
        stroke_min_m=-5e-3,
        stroke_max_m=30e-3,
        K_P_per_m=3e4,
        K_V_s_per_m=1e4,
        K_I_per_m_s=3e3,
        options=OPTIONS,
    )
