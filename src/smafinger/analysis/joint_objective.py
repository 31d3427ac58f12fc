"""The joint fit's objective: residuals of the simulated angle as a function of the fit vector.

See :class:`PhaseObjective` for the parameterisation of h = h0 + h2 T^2 (Eq. 11's heat-transfer
coefficient) by its value at a reference temperature and the share of the T^2 term there.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from ..engine.run import SimulationError
from ..parameters import ParameterError, ParameterSet
from ..profiles import ProfileError, VoltageProgram
from .data import AngleCurve
from .joint_experiments import simulate_angle

BAD_RESIDUAL_DEG = 180.0  # residual of a run that failed (blow-up, parameter out of range)
#: reference temperature T_a of the h parameterisation per phase [degC] (where the paper-like
#: curves pin h down best: inside the austenite band on heating, between the martensite band and
#: the peak temperature on cooling). Only the conditioning depends on it, not the optimum.
H_REF_C = {"heating": 90.0, "cooling": 110.0}
Q_MIN = 1e-6


class PhaseObjective:
    """Residuals (model - data, deg) of one experiment as a function of the fit vector z.

    h = h0 + h2 T^2 is parameterised by its value at a reference temperature T_a and the share
    q of the T^2 term there: h(T) = h_a ((1 - q) + q (T/T_a)^2), i.e. h0 = h_a (1 - q),
    h2 = h_a q / T_a^2. z = (log h_a, log q, log(value/start) of the other fields). With T_a
    near the temperature the curve pins down best (:data:`H_REF_C`), log h_a and log q are far
    less correlated than log h0 and log h2 (|r| 0.5-0.8 instead of 0.96-0.997), and the box
    q <= 1 is exactly h0 >= 0.
    """

    def __init__(self, base: ParameterSet, phase: str, fields: Sequence[str], start: dict[str, float],
                 experiments: Sequence[tuple[AngleCurve, VoltageProgram]],
                 on_eval: Callable[[int], None] | None):
        self.base, self.fields, self.start = base, tuple(fields), start
        self.experiments, self.on_eval = list(experiments), on_eval
        self.data = np.concatenate([c.angle_deg for c, _ in self.experiments])
        self.n_points = int(self.data.size)
        self.Ta = H_REF_C[phase]
        self.nfev = 0
        h0, h2 = start[fields[0]], start[fields[1]]
        self.ha0 = h0 + h2 * self.Ta**2
        self.q0 = max(h2 * self.Ta**2 / self.ha0, Q_MIN)
        hi_h = _field_range(fields[0])[1]
        self.bounds = [(math.log(1e-2 / self.ha0), math.log(hi_h / self.ha0)),
                       (math.log(Q_MIN / self.q0), math.log(1.0 / self.q0))]
        for f in self.fields[2:]:
            lo, hi = _field_range(f)
            s = start[f]
            self.bounds.append((math.log(max(lo, s * 1e-3) / s), math.log(hi / s)))

    def values(self, z: np.ndarray) -> dict[str, float]:
        """The fitted fields' values at the fit vector ``z``."""
        ha = self.ha0 * math.exp(z[0])
        q = min(self.q0 * math.exp(z[1]), 1.0)
        out = {self.fields[0]: ha * (1.0 - q), self.fields[1]: ha * q / self.Ta**2}
        for f, zi in zip(self.fields[2:], z[2:]):
            out[f] = float(self.start[f] * math.exp(zi))
        return out

    def z_of(self, values: dict[str, float]) -> np.ndarray:
        """The fit vector of the fields' ``values`` (inverse of :meth:`values`)."""
        h0, h2 = values[self.fields[0]], values[self.fields[1]]
        ha = h0 + h2 * self.Ta**2
        z = [math.log(ha / self.ha0), math.log(max(h2 * self.Ta**2 / ha, Q_MIN) / self.q0)]
        z += [math.log(values[f] / self.start[f]) for f in self.fields[2:]]
        return np.array(z)

    def params(self, z: np.ndarray) -> ParameterSet:
        """The base set with the values at ``z``."""
        return self.base.replace(**self.values(z))

    def residuals_at(self, values: dict[str, float]) -> np.ndarray:
        """Model minus data [deg] of all curves, :data:`BAD_RESIDUAL_DEG` where the run failed."""
        self.nfev += 1
        try:
            p = self.base.replace(**values)
            model = np.concatenate([simulate_angle(p, prog, c.t_s) for c, prog in self.experiments])
            r = model - self.data
            if not np.all(np.isfinite(r)):
                raise SimulationError("non-finite angle")
        except (SimulationError, ParameterError, ProfileError):
            r = np.full(self.n_points, BAD_RESIDUAL_DEG)
        if self.on_eval is not None:
            self.on_eval(self.nfev)
        return r

    def residuals(self, z: np.ndarray) -> np.ndarray:
        """Residuals [deg] at the fit vector ``z``."""
        return self.residuals_at(self.values(z))

    def sse(self, z: np.ndarray) -> float:
        """Sum of squared residuals [deg^2] at ``z``."""
        r = self.residuals(z)
        return float(r @ r)


def _field_range(name: str) -> tuple[float, float]:
    """The allowed (low, high) range of a ParameterSet field."""
    from ..parameters.base import field_spec

    return field_spec(name).metadata["range"]
