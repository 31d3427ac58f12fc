"""Joint geometry shared by both named sets.

Source: the authors' public Simulink model (G. Gilardi, ``gabrielegilardi/FingerControl``,
MIT licence, 2020, ``Initialization.m``), as summarised in MODEL-NOTES ("Geometry"). The
paper itself does not give these dimensions.
"""

GEOMETRY = {
    "a1_m": 12.3e-3,
    "a2_m": 6.5e-3,
    "a3_m": 14.5e-3,
    "a4_m": 17.5e-3,
    "a5_m": 1.5e-3,
    # spring-slack tendon (Sec. 1.1, 3.1; MODEL-NOTES "Springs and slack")
    "spring_K_N_m": 140.0,
    "spring_free_length_m": 9.17e-3,
    "slack_m": 7e-3,
    "slack_band_m": 1e-3,
    "slack_penalty_per_mm": 1.0,
}
