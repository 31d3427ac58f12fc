"""Figures laid out like the paper's (angle, velocity, temperatures, voltages, deformations)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _mpl():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def plot_result(result, path: str | Path | None = None, title: str | None = None):
    """Five stacked panels sharing the time axis; saved to ``path`` if given."""
    plt = _mpl()
    t = result.t
    fig, ax = plt.subplots(5, 1, figsize=(7.5, 10.5), sharex=True, constrained_layout=True)
    ax[0].plot(t, result.theta_deg, color="k", label=r"$\theta$")
    ax[0].plot(t, result.theta_ref_deg, color="tab:red", ls="--", lw=1.0, label=r"$\theta_F$ (target)")
    ax[0].set_ylabel("Joint angle [deg]")
    ax[0].legend(loc="best", fontsize=8)
    ax[1].plot(t, result.omega_deg_s, color="k")
    ax[1].set_ylabel("Angular velocity [deg/s]")
    ax[2].plot(t, result.T_upper_C, color="tab:blue", label="upper")
    ax[2].plot(t, result.T_lower_C, color="tab:orange", label="lower")
    ax[2].set_ylabel("Wire temperature [°C]")
    ax[2].legend(loc="best", fontsize=8)
    # PWM voltage averaged over each output interval is unreadable at 1 ms; show V_H x duty
    vh = result.spec.params.V_H_V
    if result.spec.strategy == "open-loop":
        vu, vl = result.V_upper_V, result.V_lower_V
        lab = "voltage [V]"
    else:
        vu, vl = vh * result.duty_upper / 100.0, vh * result.duty_lower / 100.0
        lab = r"Mean voltage $V_H\,DC\%$ [V]"
    ax[3].plot(t, vu, color="tab:blue", lw=0.8, label="upper")
    ax[3].plot(t, vl, color="tab:orange", lw=0.8, label="lower")
    ax[3].set_ylabel(lab)
    ax[3].legend(loc="best", fontsize=8)
    L = result.spec.params.wire_length_m
    eps_R = result.spec.params.eps_R
    xi0 = result.spec.params.xi_init
    ax[4].plot(t, 1e3 * result.spring_upper_m, color="tab:blue", label="upper spring")
    ax[4].plot(t, 1e3 * result.spring_lower_m, color="tab:orange", label="lower spring")
    ax[4].plot(t, 1e3 * L * eps_R * (xi0 - result.xi_upper), color="tab:blue", ls=":", label="upper wire contraction")
    ax[4].plot(t, 1e3 * L * eps_R * (xi0 - result.xi_lower), color="tab:orange", ls=":", label="lower wire contraction")
    ax[4].set_ylabel("Deformation [mm]")
    ax[4].set_xlabel("Time [s]")
    ax[4].legend(loc="best", fontsize=7, ncol=2)
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.suptitle(title or f"{result.spec.params.name}, {result.spec.strategy}")
    if path is not None:
        from .results import atomic_write

        suffix = Path(path).suffix.lstrip(".") or "png"
        atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=130, format=suffix))
        plt.close(fig)
    return fig
