"""Joint-level identification (the paper's Fig. 9): h0, h2 and C_DF from angle-vs-time curves.

Open-loop experiments on the upper (extensor) wire, the lower wire passive, each starting at rest
at the parameter set's ``theta0_deg`` with the wires at ambient; t = 0 in each file is the
moment the upper wire is switched on:

- **heating curves**: the upper wire driven from t = 0 (a voltage column, or a constant
  voltage). While it is driven the simulator uses the *heating* coefficients
  ``h0_heating, h2_heating, C_DF_heating`` and only those, so these curves identify them.
- **cooling curves**: driven for a while (a voltage column, or ``heat_s`` seconds at a
  constant voltage), then switched off; from then on the simulator uses the *cooling*
  coefficients. The heating part depends on the heating coefficients, so the fit is
  sequential: heating first, then cooling with the heating values held at their fit.

One or more curves per phase are fitted together, with the full simulator
(:func:`smafinger.simulate`, open loop). The model is nonsmooth in its parameters: the
breakaway from stiction happens on a 1 ms step, so a tiny parameter change can move it by a
step and the angle by ~0.02 deg, and branch switches and the restick add similar jumps. So no
analytic or small-step derivative is used:

1. coarse scans: a common scale factor on h (h0 and h2 together), which finds the timing
   even from a start where the model never moves within the data, then each other parameter
   on its own (a too-large M_SF can keep the joint stuck whatever h is);
2. :func:`scipy.optimize.least_squares` (trust-region reflective) with *large* central
   finite-difference steps (``diff_step`` = 1 %: secants across the jumps, not tangents of
   them). (Nelder-Mead was tried: from the same start it used its whole budget of 256 runs
   without converging, where this converges in about 80.)

Standard errors come from a 1 %-secant Jacobian in log(value) at the solution
(``s^2 (J^T J)^-1``); for a weakly identified pair (|corr(h0, h2)| > 0.99) they understate the
uncertainty, and the fit says so (``warnings``).

Identifiability of h2: h = h0 + h2 T^2 is seen only through the temperatures at which the
angle moves (the transformation bands) and the time taken to get there. h2 is identifiable when
the curves see the wire at clearly different temperatures: a *slow* heating (low voltage, so the
wire nears its steady state inside the austenite band), and *two or more* cooling curves from
different peak temperatures (different heating times). From one 8 V heating curve, or from a
single cooling curve, h0 and h2 trade off almost perfectly (docs/identification.md has numbers).

The pieces: :mod:`.joint_experiments` (voltage programs, the model's angle, synthetic curves),
:mod:`.joint_objective` (residuals of the fit vector), :mod:`.joint_phase` (the fit of one phase);
this module fits both phases and draws the figure. Their public names are importable from here.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..parameters import ParameterSet
from ..profiles import VoltageProgram
from .data import AngleCurve
# the experiments, the objective and the one-phase fit live in their own modules; their public
# names are re-exported here, where callers import them from
from .joint_experiments import (  # noqa: F401
    OFF_BELOW_V, OUTPUT_INTERVAL_S, cooling_program, heating_program, program_from_voltage, program_text,
    simulate_angle, synthesize,
)
from .joint_objective import BAD_RESIDUAL_DEG, H_REF_C, Q_MIN  # noqa: F401
from .joint_phase import (  # noqa: F401
    COORD_FACTORS, DIFF_STEP, H_CORR_WARN, MAX_RUNS, MSF_FIELD, PHASE_FIELDS, REL_SE_WARN, RESTART_TOL,
    SCAN_FACTORS, PhaseFit, fit_phase,
)

_SHORT = {"h0_heating_W_m2K": "h0", "h2_heating_W_m2K3": "h2", "C_DF_heating_Nms": "C_DF",
          "h0_cooling_W_m2K": "h0", "h2_cooling_W_m2K3": "h2", "C_DF_cooling_Nms": "C_DF", MSF_FIELD: "M_SF"}


# ---------------------------------------------------------------------------------------
# both phases
# ---------------------------------------------------------------------------------------
@dataclass
class JointFit:
    heating: PhaseFit
    cooling: PhaseFit
    params: ParameterSet  # base with all fitted values
    wall_s: float
    fit_msf: bool
    experiments: dict = field(default_factory=dict, repr=False)  # phase -> [(curve, program)]

    @property
    def values(self) -> dict[str, float]:
        v = dict(self.heating.values)
        v.update(self.cooling.values)
        return v

    @property
    def warnings(self) -> list[str]:
        return self.heating.warnings + self.cooling.warnings

    def to_dict(self) -> dict:
        return {"values": self.values, "heating": self.heating.to_dict(), "cooling": self.cooling.to_dict(),
                "wall_s": self.wall_s, "fit_msf": self.fit_msf, "warnings": self.warnings}


def fit_joint(heating: Sequence[tuple[AngleCurve, VoltageProgram]],
              cooling: Sequence[tuple[AngleCurve, VoltageProgram]], base: ParameterSet,
              fit_msf: bool = False, scan: bool = True,
              on_eval: Callable[[str, int], None] | None = None, max_nfev: int = 40) -> JointFit:
    """Fit the heating coefficients on the heating curves, then the cooling ones on the cooling
    curves (heating values held at their fit). Each list holds ``(curve, program)`` pairs (see
    :func:`heating_program`, :func:`cooling_program`). ``on_eval(phase, n)`` reports progress."""
    t0 = time.perf_counter()
    cb = (lambda ph: (lambda n: on_eval(ph, n))) if on_eval is not None else (lambda ph: None)
    hf = fit_phase("heating", heating, base, fit_msf, scan, cb("heating"), max_nfev)
    mid = base.replace(**hf.values)
    cf = fit_phase("cooling", cooling, mid, False, scan, cb("cooling"), max_nfev)
    final = mid.replace(**cf.values)
    return JointFit(hf, cf, final, time.perf_counter() - t0, fit_msf,
                    {"heating": list(heating), "cooling": list(cooling)})


def phase_budget(fit_msf: bool, scan: bool = True) -> int:
    """Typical number of simulator runs of one phase (for progress bars; may be exceeded)."""
    p = 3 + (1 if fit_msf else 0)
    n_scan = len(SCAN_FACTORS) - 1 + len(COORD_FACTORS) * (p - 1) if scan else 0
    return 1 + n_scan + 20 * (2 * p + 1) + 1 + 2 * p


def joint_figure(fit: JointFit, start: ParameterSet):
    """Measured vs fitted (and starting) angle curves: heating curves on the top row, cooling
    curves below."""
    from matplotlib.figure import Figure

    ncol = max(len(fit.experiments["heating"]), len(fit.experiments["cooling"]))
    fig = Figure(figsize=(5.5 * ncol, 7.6))
    axes = fig.subplots(2, ncol, squeeze=False)
    start_cool = start.replace(**fit.heating.values)
    for row, (phase, pf, p_start) in enumerate((("heating", fit.heating, start),
                                                ("cooling", fit.cooling, start_cool))):
        exps = fit.experiments[phase]
        for j in range(ncol):
            ax = axes[row, j]
            if j >= len(exps):
                ax.set_visible(False)
                continue
            curve, prog = exps[j]
            t = np.linspace(0.0, float(curve.t_s[-1]), 1000)
            ax.plot(curve.t_s, curve.angle_deg, ".", ms=2.0, color="0.45", label="data")
            ax.plot(t, simulate_angle(p_start, prog, t), "--", color="tab:orange", lw=1, label="start")
            ax.plot(t, simulate_angle(fit.params, prog, t), "-", color="tab:blue", lw=1.5, label="fit")
            txt = ", ".join(f"{_SHORT.get(k, k)} {v:.4g}" for k, v in pf.values.items())
            ax.set_title(f"{phase}: {Path(curve.path).name} ({program_text(prog)} V)\n{txt}\n"
                         f"RMS {pf.curves[j]['rms_deg']:.3f} deg", fontsize=8)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("angle [deg]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
