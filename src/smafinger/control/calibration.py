"""The resistance-to-position map of the self-sensing controller (Eq. S1 of :mod:`.selfsensing`).

Calibrated once, as on a bench, with a position sensor: the actuator makes a step from rest to
each of a set of targets in closed loop (the paper's PWM-PID, one wire at a time: the
independent strategy of Sec. 4.1), and the samples of each hold after :data:`SETTLE_S`
give (R_i, q). The cubic map of Eq. (S1) is fitted to them by linear least squares
(``numpy.linalg.lstsq``) on r_i = R_i / R_ref,i - 1, R_ref,i being wire i's resistance at rest.
The fit's residuals are kept (the estimate's accuracy on the calibration holds).

Why holds after steps from rest, not a sweep: the resistance sees the wire, not the mechanism.
At one position the wire's resistance differs with its history (temperature, through the
resistivity's temperature coefficients; the martensite fraction, through the phase
resistivities; on the joint the series spring's elongation), so a map fitted to a slow sweep is
off by degrees at the holds a controller makes. Fitted where it is used, it is right to tenths
of a degree there (docs/controllers.md, "Self-sensing").

The steps run at the reference numerics (RK4, 1 ms) with the PWM resolved at its edges: a
sub-step ends at every period start and duty edge, 1.6 sub-steps per step at the paper's
t_P = 1 ms, but up to 2 x 10^6 per simulated second at t_P = 1 us (there the 12 steps of 12 s
took 189 s, for a run of 0.2 s). Below
:data:`EXACT_PWM_MIN_PERIOD_S` they take the period-averaged PWM instead, where
:func:`~smafinger.engine.numerics.long_step_refusal` finds it valid for the set
(:func:`calibration_numerics`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..parameters.base import ParameterSet
from ..parameters.errors import ParameterError
from ..values import is_real, one_or_many

#: calibration targets, in the mechanism's user unit: each is a step from rest, then held
CALIBRATION_TARGETS = {
    "joint": (-34.0, -32.0, -30.0, -28.0, -26.0, -25.0, -46.0, -48.0, -50.0, -52.0, -54.0, -55.0),
    "linear-bias-spring": (0.002, 0.004, 0.006, 0.008, 0.010, 0.012, 0.014, 0.016),
}
#: each step is held this long [s]; samples from SETTLE_S on are fitted
STEP_S = 12.0
SETTLE_S = 6.0
#: polynomial degree of Eq. (S1) in each wire's r_i
DEGREE = 3
#: the shortest PWM period the calibration resolves at its edges [s]: up to 20 edges per 1 ms
#: step, about ten times the cost at the paper's t_P = 1 ms. Every shipped set is above it, so
#: their calibrations are those made with the PWM resolved, as before this limit existed
EXACT_PWM_MIN_PERIOD_S = 1e-4


@dataclass(frozen=True)
class ResistanceCalibration:
    """Eq. (S1): q_hat = c0 + sum_i (c1_i r_i + c2_i r_i^2 + c3_i r_i^3), q in SI (rad or m)."""

    wires: tuple[str, ...]
    R_ref_ohm: tuple[float, ...]
    c0: float
    c1: tuple[float, ...]
    c2: tuple[float, ...]
    c3: tuple[float, ...]
    rms_error: float  #: on the calibration run [q]
    max_error: float  #: [q]

    def __post_init__(self) -> None:
        """Refuse (ParameterError naming the field and the value) a map that would estimate NaN
        or nonsense at every tick: found by review, R_ref 0 or a NaN coefficient ran to the end
        with a NaN duty, the wire never heated, and a short coefficient tuple was an IndexError."""
        n = len(self.wires) if isinstance(self.wires, tuple) else -1
        if n < 1 or not all(isinstance(w, str) for w in self.wires):
            raise ParameterError(f"calibration: wires = {self.wires!r} is not a tuple of wire names")
        for name in ("R_ref_ohm", "c1", "c2", "c3"):
            v = getattr(self, name)
            if not isinstance(v, tuple) or len(v) != n:
                raise ParameterError(f"calibration: {name} = {v!r} needs one value per wire ({n})")
        for name in ("R_ref_ohm", "c0", "c1", "c2", "c3", "rms_error", "max_error"):
            v = getattr(self, name)
            for x in v if isinstance(v, tuple) else (v,):
                if not is_real(x) or not np.isfinite(x):
                    raise ParameterError(f"calibration: {name} = {v!r} holds {x!r}, not a finite number")
        if not all(R > 0.0 for R in self.R_ref_ohm):
            raise ParameterError(f"calibration: R_ref_ohm = {self.R_ref_ohm!r} must be above 0 ohm")
        if self.rms_error < 0.0 or self.max_error < 0.0:
            raise ParameterError(f"calibration: rms_error = {self.rms_error!r}, max_error = {self.max_error!r} "
                                 "must be at least 0")

    def estimate(self, R_ohm: np.ndarray) -> np.ndarray:
        """q_hat for resistances ``R_ohm`` (samples x wires; for one wire a 1-D series of samples,
        for several a 1-D array is one sample)."""
        R = np.asarray(R_ohm, dtype=float)
        if R.ndim == 0:  # one sample of one wire
            R = R.reshape(1, 1)
        elif R.ndim == 1:
            R = R[:, None] if len(self.wires) == 1 else R[None, :]
        if R.ndim != 2 or R.shape[1] != len(self.wires):  # a short row was an IndexError (found by an API fuzz)
            raise ParameterError(f"calibration: R_ohm has shape {np.shape(R_ohm)}; expected samples x "
                                 f"{len(self.wires)} wire(s) ({', '.join(self.wires)})")
        q = np.full(R.shape[0], self.c0)
        for i in range(len(self.wires)):
            r = R[:, i] / self.R_ref_ohm[i] - 1.0
            q += r * (self.c1[i] + r * (self.c2[i] + r * self.c3[i]))
        return q


def _design(R: np.ndarray, R_ref: np.ndarray) -> np.ndarray:
    r = R / R_ref - 1.0
    cols = [np.ones(len(R))] + [r[:, i] ** k for i in range(R.shape[1]) for k in range(1, DEGREE + 1)]
    return np.column_stack(cols)


def fit_calibration(wires: tuple[str, ...], q: np.ndarray, R_ohm: np.ndarray,
                    R_ref_ohm: np.ndarray | None = None) -> ResistanceCalibration:
    """Least-squares fit of Eq. (S1) to samples of q (SI) and R (samples x wires)."""
    q = np.asarray(q, dtype=float)
    R = np.atleast_2d(np.asarray(R_ohm, dtype=float))
    if R.shape != (len(q), len(wires)):
        raise ParameterError(f"calibration: R has shape {R.shape}, expected ({len(q)}, {len(wires)})")
    ok = np.isfinite(q) & np.isfinite(R).all(axis=1)
    if ok.sum() < 1 + DEGREE * len(wires):
        raise ParameterError(f"calibration: {int(ok.sum())} usable samples, too few for {1 + DEGREE * len(wires)} "
                             "coefficients")
    q, R = q[ok], R[ok]
    R_ref = R[0] if R_ref_ohm is None else np.asarray(R_ref_ohm, dtype=float)
    A = _design(R, R_ref)
    coef, *_ = np.linalg.lstsq(A, q, rcond=None)
    res = A @ coef - q
    per_wire = coef[1:].reshape(len(wires), DEGREE)
    return ResistanceCalibration(tuple(wires), tuple(float(x) for x in R_ref), float(coef[0]),
                                 *(tuple(float(x) for x in per_wire[:, k]) for k in range(DEGREE)),
                                 rms_error=float(np.sqrt(np.mean(res**2))), max_error=float(np.max(np.abs(res))))


def calibration_numerics(p: ParameterSet):
    """The numerics of the calibration's steps on set ``p`` (an :class:`~smafinger.engine.numerics.Numerics`).

    The reference (RK4, 1 ms or :func:`~smafinger.engine.numerics.reference_dt`'s shorter step
    on a stiff slider, the PWM resolved at its edges), except that a PWM period below
    :data:`EXACT_PWM_MIN_PERIOD_S` is averaged (RK4, 1 ms still) where the period-averaged PWM is
    valid for a closed loop of the paper's PID on ``p``: where
    :func:`~smafinger.engine.numerics.long_step_refusal` finds nothing against it, the rule a
    run's default numerics follow (the averaged drive holds when t_P is far below the wire's
    thermal time constant, :mod:`smafinger.engine.pwm`, and the hysteresis rule does not follow
    the ripple it removes). Elsewhere the PWM stays resolved, up to two sub-steps per period, as in
    the set's own runs at their defaults.
    """
    from ..engine.numerics import REFERENCE, long_step_refusal, reference_dt

    reference = dataclasses.replace(REFERENCE, dt_s=reference_dt(p))  # shorter on a stiff slider
    if p.pwm_period_s < EXACT_PWM_MIN_PERIOD_S and long_step_refusal(p, None, STEP_S) is None:
        return dataclasses.replace(reference, pwm="averaged")
    return reference


def calibrate(p: ParameterSet, targets: tuple[float, ...] | None = None, strategy: str = "independent",
              output_interval_s: float = 0.01) -> ResistanceCalibration:
    """Steps from rest to each target (user unit; default :data:`CALIBRATION_TARGETS`) with the paper's
    PID and a position sensor, and the fit of Eq. (S1) to the settled samples. The steps run at
    :func:`calibration_numerics`: the PWM resolved, unless its period is below
    :data:`EXACT_PWM_MIN_PERIOD_S` and averaging it is valid."""
    from ..engine.run import simulate

    targets = CALIBRATION_TARGETS[p.mechanism] if targets is None else tuple(one_or_many(targets))
    needed = 1 + DEGREE * len(p.wire_names)  # Eq. (S1)'s coefficients (found by an API fuzz and review:
    if len(set(targets)) < needed:         # one target, or 4 on the joint's two wires, fitted exactly)
        raise ParameterError(f"calibration: targets = {targets!r}: the cubic map (Eq. S1) of {len(p.wire_names)} "
                             f"wire(s) has {needed} coefficients and needs {needed} distinct positions at least")
    num = calibration_numerics(p)
    coord = f"{p.coordinate.name}_{p.coordinate.unit}"
    qs, Rs, R_ref = [], [], None
    for target in targets:
        r = simulate(p, strategy, f"0:{target:g}", t_end_s=STEP_S, output_interval_s=output_interval_s,
                     method=num.method, dt_s=num.dt_s, pwm=num.pwm, engine="compiled")
        R = np.column_stack([r.signal(f"R_{w}_ohm") for w in p.wire_names])
        R_ref = R[0] if R_ref is None else R_ref
        keep = r.t >= SETTLE_S
        qs.append(r.signal(coord)[keep] * p.to_si(1.0))  # deg -> rad for the joint (a scale)
        Rs.append(R[keep])
    return fit_calibration(tuple(p.wire_names), np.concatenate(qs), np.vstack(Rs), R_ref)
