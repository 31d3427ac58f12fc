"""Figure of the kinetics fit (:mod:`.kinetics_fit`): data against model, one panel per curve."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Sequence

from .data import StrainCurve
from .kinetics_model import model_curve, offset_residual, rms_strain

if TYPE_CHECKING:
    from .kinetics_fit import KineticsFit


def kinetics_figure(fit: KineticsFit, fitted: Sequence[StrainCurve], validated: Sequence[StrainCurve] = (),
                    loo: Sequence[dict] = ()):
    """Data vs model (strain in % against temperature), one panel per curve.

    Solid: the fit on all fitted curves; dashed: the leave-one-out prediction of that curve.
    Each model line is drawn with the curve's fitted offset (:func:`.kinetics_model.offset_residual`).
    """
    from matplotlib.figure import Figure

    items = [(c, "fitted") for c in fitted] + [(c, "validated") for c in validated]
    items.sort(key=lambda it: it[0].stress_MPa_mean)
    loo_by = {d["path"]: d for d in loo}
    n = len(items)
    ncol = 2 if n > 1 else 1
    nrow = math.ceil(n / ncol)
    fig = Figure(figsize=(5.2 * ncol, 3.8 * nrow))
    axes = fig.subplots(nrow, ncol, squeeze=False, sharex=True, sharey=True)
    for ax, (c, role) in zip(axes.flat, items):
        h = slice(0, c.split + 1)
        k = slice(c.split, c.n)
        ax.plot(c.T_C[h], 100 * c.strain[h], ".", ms=2.5, color="tab:red", alpha=0.6, label="data, heating")
        ax.plot(c.T_C[k], 100 * c.strain[k], ".", ms=2.5, color="tab:blue", alpha=0.6, label="data, cooling")
        _, m = model_curve(fit.params, c, fit.stress)
        m = m + offset_residual(m, c.strain)[1]
        rms = rms_strain(fit.params, c, fit.stress)
        ax.plot(c.T_C[h], 100 * m[h], "-", color="darkred", lw=1.4, label="model (all fitted)")
        ax.plot(c.T_C[k], 100 * m[k], "-", color="navy", lw=1.4)
        title = f"{c.name}: {c.stress_MPa_mean:.0f} MPa, {role}, RMS {100 * rms:.3f}%"
        if c.path in loo_by:
            _, ml = model_curve(loo_by[c.path]["params"], c, fit.stress)
            ml = ml + offset_residual(ml, c.strain)[1]
            ax.plot(c.T_C, 100 * ml, "--", color="k", lw=0.9, label="leave-one-out prediction")
            title += f"\nleft out: RMS {100 * loo_by[c.path]['rms_strain']:.3f}%"
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("temperature [degC]")
    for ax in axes[:, 0]:
        ax.set_ylabel("strain [%]")
    axes.flat[0].legend(fontsize=7, loc="lower left")
    p = fit.params
    fig.suptitle(f"cosine kinetics fit: A_S0 {p.A_S0_C:.1f}, A_F0 {p.A_F0_C:.1f}, M_S0 {p.M_S0_C:.1f}, "
                 f"M_F0 {p.M_F0_C:.1f} degC, c_A {p.c_A_Pa_per_C / 1e6:.2f}, c_M {p.c_M_Pa_per_C / 1e6:.2f} "
                 f"MPa/degC, eps_R {100 * p.eps_R:.2f}%", fontsize=9)
    fig.tight_layout()
    return fig
