"""Figures laid out like the paper's (position, velocity, temperatures, voltages, deformations).

The same five panels for any mechanism: the joint's angle in degrees, a slider's position in
millimetres.
"""

from __future__ import annotations

from pathlib import Path

from .files import atomic_write, check_output


def _mpl():
    """pyplot, on the caller's backend (the command line sets Agg for itself, ``cli.main``)."""
    import matplotlib.pyplot as plt

    return plt


#: mechanism -> (coordinate column, its reference, velocity column, axis scale, axis labels)
_AXES = {
    "joint": ("theta_deg", "theta_ref_deg", "omega_deg_s", 1.0, r"$\theta$", "Joint angle [deg]",
              "Angular velocity [deg/s]"),
    "linear-bias-spring": ("position_m", "position_ref_m", "velocity_m_s", 1e3, "x", "Position [mm]",
                           "Velocity [mm/s]"),
}
_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def plot_result(result, path: str | Path | None = None, title: str | None = None):
    """Five stacked panels sharing the time axis; saved to ``path`` if given (and then closed).

    ValueError for a run that recorded only its metrics' signals (``record="metrics"``): the
    panels need its velocity, target, drive and springs. A figure whose drawing or saving fails
    is closed before the error goes on."""
    if result.recorded is not None:
        raise ValueError("plot needs every signal, and this run recorded only its metrics' signals "
                         "(record='metrics'): run it with record='all'")
    if path is not None:
        check_output(path)
    plt = _mpl()
    fig, ax = plt.subplots(5, 1, figsize=(7.5, 10.5), sharex=True, constrained_layout=True)
    try:
        _draw(result, fig, ax, title)
        if path is not None:
            suffix = Path(path).suffix.lstrip(".") or "png"
            atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=130, format=suffix))
    except BaseException:
        plt.close(fig)
        raise
    if path is not None:
        plt.close(fig)
    return fig


def _draw(result, fig, ax, title):
    """The five panels of :func:`plot_result` on ``ax``."""
    p = result.spec.params
    q, q_ref, v, k, sym, q_label, v_label = _AXES[p.mechanism]
    t = result.t
    open_loop = result.spec.strategy == "open-loop"
    ax[0].plot(t, k * result.signal(q), color="k", label=sym)
    if not open_loop:  # open loop pursues no target
        ax[0].plot(t, k * result.signal(q_ref), color="tab:red", ls="--", lw=1.0, label="target")
    ax[0].set_ylabel(q_label)
    ax[0].legend(loc="best", fontsize=8)
    ax[1].plot(t, k * result.signal(v), color="k")
    ax[1].set_ylabel(v_label)
    for i, w in enumerate(p.wire_names):
        c = _COLORS[i % len(_COLORS)]
        ax[2].plot(t, result.signal(f"T_{w}_C"), color=c, label=w)
        # PWM voltage sampled every output interval is unreadable at 1 ms; show V_H x duty
        drive = result.signal(f"V_{w}_V") if open_loop else p.V_H_V * result.signal(f"duty_{w}") / 100.0
        ax[3].plot(t, drive, color=c, lw=0.8, label=w)
        contraction = 1e3 * p.wire_length_m * p.eps_R * (p.xi_init - result.signal(f"xi_{w}"))
        ax[4].plot(t, contraction, color=c, ls=":", label=f"{w} wire contraction")
        if p.mechanism == "joint":
            ax[4].plot(t, 1e3 * result.signal(f"spring_{w}_m"), color=c, label=f"{w} spring")
    ax[2].set_ylabel("Wire temperature [°C]")
    current = result.spec.voltage is not None and result.spec.voltage.kind == "current"
    ax[3].set_ylabel(("Drive current [A]" if current else "Drive [V]") if open_loop
                     else r"Mean voltage $V_H\,DC\%$ [V]")
    ax[4].set_ylabel("Deformation [mm]")
    ax[4].set_xlabel("Time [s]")
    for a in ax[2:]:
        a.legend(loc="best", fontsize=7, ncol=2)
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.suptitle(title or f"{p.name}, {result.spec.strategy}")
