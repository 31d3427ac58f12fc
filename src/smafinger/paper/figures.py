"""The figures, laid out like the paper's: ``plot(runs, title, path, ...)`` per layout.

Each function draws the successful runs of one output figure (:class:`~.scenario.Figure`)
from their thinned results and their figure metrics (``run.derived``); runs are styled in
the order the figure lists them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..metrics import window
from ..files import atomic_write

#: line colour and style of the 1st, 2nd, ... run of a panel
STYLES = (("tab:blue", "-"), ("tab:orange", "-."), ("tab:green", "--"), ("tab:red", ":"))
STRATEGY_COLORS = {"independent": "tab:blue", "cooperative": "tab:red"}
#: open loop: the cooling panel shows until every curve is within this of its end [deg]
SETTLED_DEG = 0.05


#: the figures' style, applied inside each figure's drawing only (the caller's rcParams are left alone)
STYLE = {"font.size": 9, "axes.titlesize": 9.5, "legend.fontsize": 8, "axes.grid": True, "grid.alpha": 0.3}


def _plt():
    import matplotlib.pyplot as plt  # on the caller's backend (the command line's: Agg, cli.main)

    return plt


def _styled(draw):
    """``draw`` under :data:`STYLE` (``matplotlib.rc_context``): it used to update the process's
    rcParams for good, so the bench's figures drawn after a reproduce in the same process came
    out different from those drawn in a fresh worker."""
    import functools

    @functools.wraps(draw)
    def styled(*args, **kwargs):
        with _plt().rc_context(STYLE):
            return draw(*args, **kwargs)
    return styled


def _save(fig, path: Path) -> None:
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=150, format="png"))
    _plt().close(fig)


def _legends(axes) -> None:
    for a in np.ravel(axes):
        if a.has_data():
            a.legend(loc="best")


def _panels(runs: list, panels: tuple[str, ...]) -> list[list]:
    return [[r for r in runs if r.ok and r.scenario.panel == p] for p in panels]


@_styled
def openloop(runs: list, title: str, path: Path) -> None:
    """2 x 2: rows upper / lower wire heated; (a) heating phase, (b) cooling phase (Figs. 7-8)."""
    plt = _plt()
    fig, ax = plt.subplots(2, 2, figsize=(10, 7.2), constrained_layout=True)
    cmap = plt.get_cmap("viridis")
    cool_end, t_off = 2.0, 0.0
    for row, sel in enumerate(_panels(runs, ("upper", "lower"))):
        sel = sorted(sel, key=lambda r: r.scenario.value)
        for k, r in enumerate(sel):
            c = cmap(0.1 + 0.75 * k / max(1, len(sel) - 1))
            ls = ("-", "--", "-.", ":")[k % 4]
            t_off = r.scenario.derive.t_off_s
            t, th = r.result.t, r.result.signal("theta_deg")
            h = window(t, end_s=t_off)
            ax[row, 0].plot(t[h], th[h], color=c, ls=ls, label=r.scenario.label)
            ax[row, 1].plot(t[~h] - t_off, th[~h], color=c, ls=ls, label=r.scenario.label)
            moving = np.flatnonzero(~h & (np.abs(th - th[-1]) > SETTLED_DEG))
            if moving.size:
                cool_end = max(cool_end, float(t[moving[-1]] - t_off))
    for row, what in enumerate(("upper wire heated (extension)", "lower wire heated (flexion)")):
        ax[row, 1].set_xlim(0.0, min(cool_end + 2.0, t_off) if t_off else cool_end + 2.0)
        ax[row, 0].set_title(f"({'ac'[row]}) Heating phase: {what}")
        ax[row, 1].set_title(f"({'bd'[row]}) Cooling phase: voltage removed")
        ax[row, 0].set_xlabel("Time [s]")
        ax[row, 1].set_xlabel("Time since the voltage was removed [s]")
        for a in ax[row]:
            a.set_ylabel(r"Joint angle $\theta$ [deg]")
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def cooling_phase(runs: list, title: str, path: Path, panel: str, zoom_deg: float | None = None,
                  marks=None) -> None:
    """Fig. 11: the angle (and, with ``zoom_deg``, a close-up of +-zoom_deg around the last
    target) and the agonist's temperature, controller on vs off in its cooling phase.

    ``marks(run) -> (target_deg, direction, overshoot_deg)``: the overshoot the claim reads
    (in the direction of the move), drawn as a dotted level in the run's colour.
    """
    plt = _plt()
    rows = 3 if zoom_deg else 2
    fig, ax = plt.subplots(rows, 1, figsize=(7.5, 3.2 * rows + 0.6), sharex=True, constrained_layout=True)
    angle_axes = [ax[0], ax[1]] if zoom_deg else [ax[0]]
    target = None
    for k, r in enumerate(r for r in runs if r.ok):
        res, (c, ls) = r.result, STYLES[k % len(STYLES)]
        if target is None:
            for a in angle_axes:
                a.plot(res.t, res.signal("theta_ref_deg"), color="k", ls="--", lw=1.0, label=r"target $\theta_F$")
            target = float(res.signal("theta_ref_deg")[-1])
        for a in angle_axes:
            a.plot(res.t, res.signal("theta_deg"), color=c, ls=ls, label=r.scenario.label)
        if marks is not None:
            aim, direction, ov = marks(r)
            angle_axes[-1].axhline(aim + direction * ov, color=c, ls=":", lw=1.2,
                                   label=f"{r.scenario.label}: overshoot {ov:.3f} deg")
        ax[-1].plot(res.t, res.signal(f"T_{r.scenario.wire}_C"), color=c, ls=ls, label=r.scenario.label)
    ax[0].set_ylabel(r"Joint angle $\theta$ [deg]")
    ax[0].set_title(panel)
    if zoom_deg and target is not None:
        ax[1].set_ylim(target - zoom_deg, target + zoom_deg)
        ax[1].set_ylabel(r"Joint angle $\theta$ [deg]")
        ax[1].set_title(f"(b) Close-up, +-{zoom_deg:g} deg" + ("; dotted: overshoot in the direction of the move"
                                                               if marks else ""))
    ax[-1].set_ylabel("Agonist wire temperature [°C]")
    ax[-1].set_xlabel("Time [s]")
    ax[-1].set_title(f"({'c' if zoom_deg else 'b'}) Agonist wire temperature")
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def onoff_cycles(runs: list, title: str, path: Path) -> None:
    """Fig. 10(a): open-loop on/off cycles. (a) the air inside the casing (two-node model),
    (b) the wire's temperature, (c) the joint angle, (d) the cooling time of each cycle's move,
    per thermal model."""
    plt = _plt()
    fig, ax = plt.subplots(4, 1, figsize=(8.0, 12.0), constrained_layout=True)
    ok = [r for r in runs if r.ok]
    for k, r in enumerate(ok):
        res, (c, ls), w = r.result, STYLES[k % len(STYLES)], r.scenario.wire
        cyc = r.derived["cycles"]
        if r.spec.params.thermal_model == "two-node":
            ax[0].plot(res.t, res.signal(f"T_casing_{w}_C"), color=c, lw=1.6, label=r.scenario.label)
            ax[0].axhline(r.spec.params.T_amb_C, color="k", ls="--", lw=0.8, label="open air (ambient)")
        ax[1].plot(res.t, res.signal(f"T_{w}_C"), color=c, ls=ls, lw=1.0, label=r.scenario.label)
        ax[2].plot(res.t, res.signal("theta_deg"), color=c, ls=ls, label=r.scenario.label)
        cool = [np.nan if x["cooling_s"] is None else x["cooling_s"] for x in cyc]
        ax[3].plot(np.arange(1, len(cyc) + 1), cool, color=c, ls=ls, marker="o", label=r.scenario.label)
        if k == 0:
            for a in ax[:3]:
                for x in cyc:
                    a.axvspan(x["on_s"], x["off_s"], color="tab:orange", alpha=0.08)
    titles = ("(a) Air inside the actuator casing (shaded: voltage on)", "(b) Wire temperature",
              "(c) Joint angle", "(d) Cooling time of each move: 90% of the way back after the switch-off")
    for a, t, y in zip(ax, titles, ("Temperature [°C]", "Temperature [°C]", r"Joint angle $\theta$ [deg]",
                                    "Cooling time [s]")):
        a.set_title(t)
        a.set_ylabel(y)
    for a in ax[:3]:
        a.set_xlabel("Time [s]")
    ax[3].set_xlabel("Cycle")
    ax[3].set_xticks(np.arange(1, 1 + max((len(r.derived["cycles"]) for r in ok), default=0)))
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def moves(runs: list, title: str, path: Path) -> None:
    """Fig. 12: closed-loop move with one actuator and the return through its cooling phase
    (columns extension / flexion): angle and agonist temperature."""
    plt = _plt()
    fig, ax = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True, constrained_layout=True)
    for col, sel in enumerate(_panels(runs, ("extension", "flexion"))):
        for r in sel:
            res, wire = r.result, r.scenario.wire
            ax[0, col].plot(res.t, res.signal("theta_ref_deg"), color="k", ls="--", lw=1.0, label=r"target $\theta_F$")
            ax[0, col].plot(res.t, res.signal("theta_deg"), color="tab:blue", label=r"joint angle $\theta$")
            ax[1, col].plot(res.t, res.signal(f"T_{wire}_C"), color="tab:red", label=f"{wire} wire (agonist)")
            ret = r.derived["return"]
            if ret["reached_s"] is not None:
                ax[0, col].axvspan(ret["start_s"], ret["start_s"] + ret["reached_s"], color="tab:gray", alpha=0.15,
                                   label=f"cooling phase to reach: {ret['reached_s']:.1f} s")
            ax[0, col].set_title(f"({'ab'[col]}) {r.scenario.label}")
        ax[0, col].set_ylabel(r"Joint angle $\theta$ [deg]")
        ax[1, col].set_ylabel("Agonist wire temperature [°C]")
        ax[1, col].set_xlabel("Time [s]")
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def returns(runs: list, title: str, path: Path) -> None:
    """Fig. 13: the return from a move, agonist only vs co-operative (columns extension /
    flexion), on a time axis from the start of the return."""
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    for col, (kind, sel) in enumerate(zip(("Extension", "Flexion"), _panels(runs, ("extension", "flexion")))):
        for k, r in enumerate(sel):
            res, ret = r.result, r.derived["return"]
            c, ls = STYLES[k % len(STYLES)]
            m = window(res.t, ret["start_s"])
            lab = r.scenario.label + ("" if ret["reached_s"] is None else
                                      f" (reaches {ret['target_deg']:g} deg in {ret['reached_s']:.1f} s)")
            ax[col].plot(res.t[m] - ret["start_s"], res.signal("theta_deg")[m], color=c, ls=ls, label=lab)
        if sel:
            back, move = sel[0].derived["return"]["target_deg"], sel[0].derived["move"]["target_deg"]
            ax[col].axhline(back, color="k", ls="--", lw=1.0, label=rf"target $\theta_F$ = {back:g} deg")
            ax[col].set_title(f"({'ab'[col]}) {kind}: cooling phase after {move:g} deg")
        ax[col].set_xlabel("Time since the return was commanded [s]")
        ax[col].set_ylabel(r"Joint angle $\theta$ [deg]")
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def cycles(runs: list, title: str, path: Path, panels: dict[str, str], paper_s: dict[str, float]) -> None:
    """Fig. 15: full cycles, one panel per reading (``panels``: panel -> title). Dashed: the
    time at which each run reaches its last target (``elapsed_s``, given in the legend with
    the cycle time); dotted: the paper's cycle times ``paper_s`` (strategy -> s). A second
    run of the same strategy in a panel (an earlier reading) is drawn thin and dashed."""
    plt = _plt()
    fig, ax = plt.subplots(len(panels), 1, figsize=(9.0, 5.2 * len(panels)), constrained_layout=True)
    ax = np.atleast_1d(ax)
    for row, (sel, panel_title) in enumerate(zip(_panels(runs, tuple(panels)), panels.values())):
        t_max = 0.0
        for i, r in enumerate(sel):
            res, c = r.result, STRATEGY_COLORS[r.spec.strategy]
            first = r.spec.strategy not in {x.spec.strategy for x in sel[:i]}
            end, cyc = r.derived["elapsed_s"], r.derived["cycle_s"]
            lab = r.scenario.label + (": cycle not completed" if end is None else
                                      f": last target reached at t = {end:.1f} s (cycle time {cyc:.1f} s)")
            if first:
                ax[row].plot(res.t, res.signal("theta_ref_deg"), color=c, ls=":", lw=1.0)
            ax[row].plot(res.t, res.signal("theta_deg"), color=c, label=lab,
                         **({} if first else {"ls": "--", "lw": 0.8, "alpha": 0.7}))
            if end is not None:
                ax[row].axvline(end, color=c, ls="--", lw=0.8, alpha=1.0 if first else 0.5)
                t_max = max(t_max, end)
        for strat, v in paper_s.items():
            ax[row].axvline(v, color=STRATEGY_COLORS[strat], ls=(0, (1, 3)), lw=1.5, alpha=0.6)
        ax[row].plot([], [], color="gray", ls=":", lw=1.0, label=r"targets $\theta_F$")
        ax[row].plot([], [], color="gray", ls="--", lw=0.8, label="last target reached (smafinger)")
        ax[row].plot([], [], color="gray", ls=(0, (1, 3)), lw=1.5,
                     label="cycle end in the paper (" + " / ".join(f"{v:g}" for v in paper_s.values()) + " s)")
        unfinished = [r.spec.t_end_s for r in sel if r.derived["elapsed_s"] is None]
        ax[row].set_xlim(0, max(40.0, t_max + 2.0, *paper_s.values(), *unfinished))
        ax[row].set_title(panel_title)
        ax[row].set_xlabel("Time [s]")
        ax[row].set_ylabel(r"Joint angle $\theta$ [deg]")
        ax[row].legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=7)
    fig.suptitle(title)
    _save(fig, path)


@_styled
def profiles(runs: list, title: str, path: Path) -> None:
    """The authors' 2020 example profiles (one column each): angle and both wires' temperatures."""
    plt = _plt()
    fig, ax = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True, constrained_layout=True)
    for col, r in enumerate(r for r in runs if r.ok):
        res = r.result
        ax[0, col].plot(res.t, res.signal("theta_ref_deg"), color="k", ls="--", lw=1.0, label=r"target $\theta_F$")
        ax[0, col].plot(res.t, res.signal("theta_deg"), color="tab:blue", label=r"joint angle $\theta$")
        ax[1, col].plot(res.t, res.signal("T_upper_C"), color="tab:blue", label="upper wire (SMA1)")
        ax[1, col].plot(res.t, res.signal("T_lower_C"), color="tab:orange", label="lower wire (SMA2)")
        ax[0, col].set_title(f"({'ab'[col]}) {r.scenario.label}")
        ax[0, col].set_ylabel(r"Joint angle $\theta$ [deg]")
        ax[1, col].set_ylabel("Wire temperature [°C]")
        ax[1, col].set_xlabel("Time [s]")
    _legends(ax)
    fig.suptitle(title)
    _save(fig, path)


__all__ = ["openloop", "cooling_phase", "onoff_cycles", "moves", "returns", "cycles", "profiles"]
