"""Identification end to end, as ``smafinger identify`` runs it: load and check the data,
fit, and make the fitted parameter file, the report and the lines to print.

- :func:`identify_kinetics`: the cosine kinetics (Eqs. 9-10) from strain-temperature curves
  (:mod:`.kinetics_fit`);
- :func:`identify_joint`: h0, h2 and C_DF of the heating and cooling phases from the joint's
  angle curves (the paper's Fig. 9, :mod:`.joint_fit`).

Each returns an :class:`Identification`; bad data raises :class:`~.data.DataError`, fitted
values that do not form a valid parameter set :class:`IdentificationError`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from .data import DataError, load_angle_curve, load_strain_curve, parameter_file_text, same_data

#: parameter-name endings -> units, for printing fitted values (the unit is in every name)
UNIT_SUFFIXES = (("_Pa_per_C", "Pa/degC"), ("_W_m2K3", "W/(m^2 K^3)"), ("_W_m2K", "W/(m^2 K)"), ("_Nms", "N m s"),
                 ("_Nm", "N m"), ("_Pa", "Pa"), ("_C", "degC"))


class IdentificationError(ValueError):
    """The data give fitted values that do not form a valid parameter set (bad input: the
    data, or the base set, must change)."""


def unit_of(name: str) -> str:
    """The unit of a parameter, read from its name (``c_A_Pa_per_C`` -> ``Pa/degC``)."""
    return next((unit for suffix, unit in UNIT_SUFFIXES if name.endswith(suffix)), "")


@dataclass
class Identification:
    """What an identification made: the parameter file, the report, the text to print."""

    toml: str
    report: dict
    lines: list[str]
    warnings: list[str]
    figure: Callable[[], object] = field(repr=False)


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _toml(values: dict, base_spec, command: str, files: str) -> str:
    from ..parameters import ParameterError

    try:
        return parameter_file_text(values, base_spec, f"{command}-fit", f"smafinger identify {command} on {files}")
    except ParameterError as exc:
        raise IdentificationError(f"{files}: the fit gives no valid parameter set ({exc}); check the data") from None


# ---------------------------------------------------------------------------------------
# kinetics
# ---------------------------------------------------------------------------------------
def identify_kinetics(files: Sequence[Path], validate: Sequence[Path], base, base_spec, fit_moduli: bool = True,
                      stress: str = "mean", loo: bool = True, display=None) -> Identification:
    """Fit the cosine kinetics to ``files`` at once; predict ``validate``; with ``loo`` and at
    least 3 files, the leave-one-level-out check. ``base_spec``: the registry name or the set
    the parameter file starts from. ``display``: a :class:`smafinger.progress.Display`."""
    from . import kinetics_fit as kf

    fitted = [load_strain_curve(f) for f in files]
    validated = [load_strain_curve(f) for f in validate]
    if (copy := same_data((c.path, (c.T_C, c.strain, c.stress_Pa)) for c in fitted + validated)) is not None:
        raise DataError(copy)
    t0 = time.perf_counter()
    moduli = ("D_M",) if fit_moduli else ()
    n_loo = len(fitted) if (loo and len(fitted) >= 3) else 0
    task = display.task("kinetics fit", 1 + n_loo, "fits") if display is not None else None
    fit = kf.fit_kinetics(fitted, base, moduli, stress)
    if task:
        task.update(advance=1)
    loo_res = []
    if n_loo:
        loo_res = kf.leave_one_out(fitted, base, moduli, stress,
                                   on_fit=lambda i, name: task and task.update(advance=1, note=f"left out {name}"))
    wall = time.perf_counter() - t0
    values = {k: v for k, v in fit.params.as_dict().items() if k in fit.fitted}
    problems = kf.plausibility(fit.params)
    names = ", ".join(c.name for c in fitted)
    toml = _toml(values, base_spec, "kinetics", names)
    files_rep = [{"path": c.path, "role": "fitted", "stress_MPa": c.stress_MPa_mean, "n_points": c.n,
                  "rms_strain": fit.rms[c.path], "offset_strain": fit.offsets[c.path]} for c in fitted]
    files_rep += [{"path": c.path, "role": "validated", "stress_MPa": c.stress_MPa_mean, "n_points": c.n,
                   "rms_strain": kf.rms_strain(fit.params, c, stress),
                   "offset_strain": kf.curve_offset(fit.params, c, stress)} for c in validated]
    report = {**fit.to_dict(), "files": files_rep,
              "leave_one_out": [{k: v for k, v in d.items() if k != "params"} for d in loo_res],
              "plausible": not problems, "problems": problems, "at_bounds": fit.at_bounds, "wall_s": wall}
    lines = [f"fitted {len(fitted)} curve(s), {fit.n_points} points; stress model: {stress}; "
             f"{fit.nfev} evaluations, {wall:.1f} s"]
    for k in fit.fitted:
        lines.append(f"  {k:<14} = {_fmt(values[k]):>11} +- {fit.stderr[k]:<9.3g} (+- {fit.stderr_ar1[k]:.3g} "
                     f"allowing for correlated residuals) {unit_of(k)}".rstrip())
    lines.append("RMS strain error per curve (and its fitted strain offset, the austenite level in its zero):")
    lines += [f"  {Path(d['path']).name:<28} {d['stress_MPa']:7.1f} MPa  {d['role']:<9}  "
              f"{d['rms_strain']:.3e} ({100 * d['rms_strain']:.3f}% strain)  "
              f"offset {100 * d['offset_strain']:+.3f}%" for d in files_rep]
    if loo_res:
        lines.append("leave-one-level-out (fit on the others, predict this one):")
        lines += [f"  {Path(d['path']).name:<28} {d['stress_MPa']:7.1f} MPa  predicted  "
                  f"{d['rms_strain']:.3e} ({100 * d['rms_strain']:.3f}% strain)" for d in loo_res]
    elif loo and len(fitted) < 3:
        lines.append("leave-one-level-out: skipped (needs at least 3 fitted files)")
    lines += [f"note: {note}" for note in fit.notes]
    warnings = (["not physically plausible: " + "; ".join(problems)] if problems else []) + (
        ["at a bound of the search (check the data): " + ", ".join(fit.at_bounds)] if fit.at_bounds else [])
    return Identification(toml, report, lines, warnings,
                          lambda: kf.kinetics_figure(fit, fitted, validated, loo_res))


# ---------------------------------------------------------------------------------------
# joint
# ---------------------------------------------------------------------------------------
def joint_experiments(heating: Sequence[Path], cooling: Sequence[Path], heat_s: Sequence[float],
                      heating_voltage: float, cooling_voltage: float):
    """The ``(curve, program)`` pairs of the heating and the cooling files (checked)."""
    from . import joint_fit as jf

    for opt, v in (("--heating-voltage", heating_voltage), ("--cooling-voltage", cooling_voltage)):
        if not (math.isfinite(v) and 0.0 < v <= 100.0):
            raise DataError(f"{opt} {v:g}: must be in (0, 100] V")
    if heat_s and len(heat_s) != len(cooling):
        raise DataError(f"--heat-s given {len(heat_s)} time(s) for {len(cooling)} --cooling file(s): give one "
                        f"per cooling file, in the same order, or none (voltage columns)")
    h_curves = [load_angle_curve(f) for f in heating]
    c_curves = [load_angle_curve(f) for f in cooling]
    try:
        experiments = ([(c, jf.heating_program(c, heating_voltage)) for c in h_curves],
                       [(c, jf.cooling_program(c, cooling_voltage, heat_s[i] if heat_s else None))
                        for i, c in enumerate(c_curves)])
    except ValueError as exc:
        raise DataError(str(exc)) from None
    if (copy := same_data((c.path, (c.t_s, c.angle_deg)) for c in h_curves + c_curves)) is not None:
        raise DataError(copy)
    return experiments


def identify_joint(h_exps, c_exps, base, base_spec, fit_msf: bool = False, display=None) -> Identification:
    """Fit h0, h2, C_DF of the heating then the cooling phase (:func:`.joint_fit.fit_joint`)
    to the experiments of :func:`joint_experiments`."""
    from . import joint_fit as jf

    t0 = time.perf_counter()
    budget = jf.phase_budget(fit_msf)
    tasks = {}
    if display is not None:
        tasks = {ph: display.task(f"joint: {ph} fit", budget, "runs") for ph in ("heating", "cooling")}

    def on_eval(phase: str, n: int) -> None:
        if phase in tasks:
            tasks[phase].update(completed=min(n, budget - 1))

    try:
        fit = jf.fit_joint(h_exps, c_exps, base, fit_msf=fit_msf, on_eval=on_eval)
    except ValueError as exc:
        raise DataError(str(exc)) from None
    for task in tasks.values():
        task.update(completed=budget)
    wall = time.perf_counter() - t0
    names = ", ".join(Path(c.path).name for c, _ in list(h_exps) + list(c_exps))
    toml = _toml(fit.values, base_spec, "joint", names)
    lines = [f"fitted {len(h_exps)} heating and {len(c_exps)} cooling curve(s) in {wall:.1f} s "
             f"({fit.heating.nfev + fit.cooling.nfev} simulations)"]
    for pf in (fit.heating, fit.cooling):
        lines.append(f"{pf.phase}: RMS {pf.rms_deg:.4f} deg (start {pf.rms_start_deg:.3f} deg)")
        lines += [f"  {k:<18} = {_fmt(pf.values[k]):>11} +- {pf.stderr[k]:<9.3g} ({100 * pf.rel_stderr[k]:.2g}%), "
                  f"start {_fmt(pf.start[k])} {unit_of(k)}".rstrip() for k in pf.fields]
        lines += [f"  {Path(d['path']).name:<28} program {d['program']:<18} RMS {d['rms_deg']:.4f} deg"
                  for d in pf.curves]
    return Identification(toml, {**fit.to_dict(), "wall_s": wall}, lines, list(fit.warnings),
                          lambda: jf.joint_figure(fit, base))
