"""PWM-PID control (Eq. 12) and the agonist-antagonist strategies (Sec. 2.6, 4)."""
