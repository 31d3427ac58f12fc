"""The model of :mod:`.kinetics_fit`: strain along a strain-temperature curve under load (Eqs. 9-10).

``strain_i = eps_R xi_i + sigma_i (1/D(xi_i) - 1/D_A)``, ``D(xi) = D_A + xi (D_M - D_A)``, with
``xi`` from the package's own kinetics (heating branch, Eq. 9, up to the maximum temperature,
then the cooling branch, Eq. 10, with the simulator's minor-loop rule); see :mod:`.kinetics_fit`.
That strain is measured from the austenite state at the curve's stress; the measured curve adds
its own offset (the sensor's zero), profiled out by :func:`offset_residual` (the one place that
rule lives). Also the fit vector (the kinetics parameters in the units and differences the fit
works in).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..jit import njit
from ..model.kinetics import COOLING, HEATING, branch_start, martensite_fraction
from ..parameters import ParameterSet
from .data import StrainCurve

#: ParameterSet fields this fit produces
KINETIC_FIELDS = ("A_S0_C", "A_F0_C", "M_S0_C", "M_F0_C", "c_A_Pa_per_C", "c_M_Pa_per_C", "eps_R",
                  "D_A_Pa", "D_M_Pa")

#: the fit vector: A_S0, A_F0-A_S0, M_F0, M_S0-M_F0 [degC], c_A, c_M [MPa/degC], eps_R [%],
#: D_M, D_A [GPa]
X_NAMES = ("A_S0", "wA", "M_F0", "wM", "c_A", "c_M", "eps_R", "D_M", "D_A")
X_LO = np.array([-100.0, 0.5, -100.0, 0.5, 0.5, 0.5, 0.01, 1.0, 1.0])
X_HI = np.array([300.0, 200.0, 300.0, 200.0, 200.0, 200.0, 20.0, 1000.0, 1000.0])
X_SCALE = np.array([5.0, 5.0, 5.0, 5.0, 1.0, 1.0, 0.2, 5.0, 5.0])


@njit(cache=True)
def strain_path(T, sigma, split, A_S0, A_F0, c_A, M_S0, M_F0, c_M, eps_R, D_A, D_M, xi_out, eps_out):
    """xi and model strain along one curve (heating branch to ``split``, then cooling)."""
    n = T.shape[0]
    xi = 1.0
    start = branch_start(HEATING, xi, T[0], sigma[0], A_S0, A_F0, c_A, M_S0, M_F0, c_M)
    branch = HEATING
    for i in range(n):
        if i == split + 1:
            # reversal: re-solve the cooling branch's start at the last heating state
            start = branch_start(COOLING, xi, T[split], sigma[split], A_S0, A_F0, c_A, M_S0, M_F0, c_M)
            branch = COOLING
        xi = martensite_fraction(branch, start, xi, T[i], sigma[i], A_S0, A_F0, c_A, M_S0, M_F0, c_M)[0]
        D = D_A + xi * (D_M - D_A)
        xi_out[i] = xi
        eps_out[i] = eps_R * xi + sigma[i] * (1.0 / D - 1.0 / D_A)


@dataclass(frozen=True)
class KineticParams:
    """The kinetics parameters in ParameterSet units (degC, Pa/degC, Pa)."""

    A_S0_C: float
    A_F0_C: float
    M_S0_C: float
    M_F0_C: float
    c_A_Pa_per_C: float
    c_M_Pa_per_C: float
    eps_R: float
    D_A_Pa: float
    D_M_Pa: float

    @classmethod
    def from_set(cls, p: ParameterSet) -> "KineticParams":
        return cls(**{k: float(getattr(p, k)) for k in KINETIC_FIELDS})

    def as_dict(self) -> dict[str, float]:
        return {k: float(getattr(self, k)) for k in KINETIC_FIELDS}

    def _x(self) -> np.ndarray:
        return np.array([self.A_S0_C, self.A_F0_C - self.A_S0_C, self.M_F0_C, self.M_S0_C - self.M_F0_C,
                         self.c_A_Pa_per_C / 1e6, self.c_M_Pa_per_C / 1e6, self.eps_R * 100.0,
                         self.D_M_Pa / 1e9, self.D_A_Pa / 1e9])

    @classmethod
    def _from_x(cls, x: np.ndarray) -> "KineticParams":
        return cls(A_S0_C=x[0], A_F0_C=x[0] + x[1], M_S0_C=x[2] + x[3], M_F0_C=x[2],
                   c_A_Pa_per_C=x[4] * 1e6, c_M_Pa_per_C=x[5] * 1e6, eps_R=x[6] / 100.0,
                   D_A_Pa=x[8] * 1e9, D_M_Pa=x[7] * 1e9)


#: linear map from the fit vector x to the fields (in field units), for the delta method
X_TO_FIELDS = np.zeros((len(KINETIC_FIELDS), len(X_NAMES)))
for _r, _entries in enumerate((((0, 1.0),), ((0, 1.0), (1, 1.0)), ((2, 1.0), (3, 1.0)), ((2, 1.0),),
                               ((4, 1e6),), ((5, 1e6),), ((6, 0.01),), ((8, 1e9),), ((7, 1e9),))):
    for _c, _v in _entries:
        X_TO_FIELDS[_r, _c] = _v


def curve_stress(curve: StrainCurve, stress: str = "mean") -> np.ndarray:
    """The stress [Pa] the model uses for each row (``"mean"`` or ``"row"``)."""
    if stress == "mean":
        return np.full(curve.n, float(np.mean(curve.stress_Pa)))
    if stress == "row":
        return np.asarray(curve.stress_Pa, dtype=float)
    raise ValueError(f"stress = {stress!r} is not one of mean, row")


def model_curve(kp: KineticParams, curve: StrainCurve, stress: str = "mean") -> tuple[np.ndarray, np.ndarray]:
    """(xi, strain) of the model along a measured curve."""
    sig = curve_stress(curve, stress)
    xi = np.empty(curve.n)
    eps = np.empty(curve.n)
    strain_path(np.ascontiguousarray(curve.T_C, dtype=float), sig, int(curve.split), kp.A_S0_C, kp.A_F0_C,
                kp.c_A_Pa_per_C, kp.M_S0_C, kp.M_F0_C, kp.c_M_Pa_per_C, kp.eps_R, kp.D_A_Pa, kp.D_M_Pa,
                xi, eps)
    return xi, eps


def offset_residual(model: np.ndarray, measured: np.ndarray) -> tuple[np.ndarray, float]:
    """Residual of one curve with its strain offset profiled out.

    The zero of a measured strain curve is arbitrary (the sensor's zero, and the loader's shift
    to the curve's minimum, which noise pulls below the austenite level): the curve is modelled
    as ``model + offset``, one constant per curve. For given kinetics the least-squares offset
    is the mean of ``measured - model`` (variable projection), so the fit never sees it as an
    unknown, yet its standard errors include it (the Jacobian of the projected residual).

    Parameters
    ----------
    model : ndarray
        The model strain along the curve (:func:`model_curve`, from the austenite state).
    measured : ndarray
        The curve's measured strain.

    Returns
    -------
    residual : ndarray
        ``model + offset - measured``.
    offset : float
        The fitted offset: the measured strain of the austenite state, in the curve's zero.
    """
    offset = float(np.mean(measured - model))
    return model + offset - measured, offset


def curve_offset(kp: KineticParams, curve: StrainCurve, stress: str = "mean") -> float:
    """The strain offset of a curve under ``kp`` (:func:`offset_residual`)."""
    return offset_residual(model_curve(kp, curve, stress)[1], curve.strain)[1]


def rms_strain(kp: KineticParams, curve: StrainCurve, stress: str = "mean") -> float:
    """RMS of (model + offset - measured) strain over a curve, its offset fitted
    (:func:`offset_residual`): for a curve not in the fit, the one thing fitted to it."""
    r = offset_residual(model_curve(kp, curve, stress)[1], curve.strain)[0]
    return float(np.sqrt(np.mean(r * r)))
