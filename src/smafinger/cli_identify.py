"""``smafinger identify``: fit model parameters to measured data.

- ``smafinger identify kinetics FILE... [--validate FILE...]``: the wire's cosine kinetics
  (Eqs. 9-10) from strain-temperature curves under constant load.
- ``smafinger identify joint --heating FILE --cooling FILE``: h0, h2 and C_DF of the heating
  and cooling phases from the joint's angle-vs-time curves (the paper's Fig. 9).

Bad input (data, options, parameter files) prints one line and exits with status 2; nothing is
written. Outputs are written only after everything succeeded, each to a temporary file first,
then all renamed into place.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Callable, List, Optional

import typer

from .analysis.data import DataError, load_angle_curve, load_strain_curve, parameter_file_text
from .engine.run import SimulationError
from .parameters import REGISTRY, ParameterError, resolve
from .profiles import ProfileError
from .results import temp_path

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  rich_markup_mode=None, help="Fit model parameters to measured data.")

_INPUT_ERRORS = (DataError, ParameterError, ProfileError, ValueError)


def _fail(cmd: str, msg: str, code: int = 2) -> None:
    first = str(msg).splitlines()[0] if str(msg) else "error"
    typer.echo(f"smafinger identify {cmd}: error: {first}", err=True)
    raise typer.Exit(code)


def _check_out(cmd: str, opt: str, path: Optional[Path], suffixes: tuple[str, ...]) -> None:
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        _fail(cmd, f"{opt} {path}: the file name must end in {' or '.join(suffixes)}")
    if not path.parent.exists():
        _fail(cmd, f"{opt} {path}: directory {path.parent} does not exist")
    if path.exists() and path.is_dir():
        _fail(cmd, f"{opt} {path}: is a directory")


def _base(cmd: str, params: str, overrides: list[str]):
    """(ParameterSet, what to write as the TOML base: a registry name or the set itself)."""
    try:
        p = resolve(params).with_overrides(overrides)
    except ParameterError as exc:
        _fail(cmd, str(exc))
    base = params if (params in REGISTRY and not overrides) else p
    return p, base


def _commit(outputs: list[tuple[Path, Callable[[str], None]]]) -> None:
    """Write every output to a temporary file beside it, then rename all into place."""
    tmps: list[tuple[Path, Path]] = []
    try:
        for path, write in outputs:
            tmp = temp_path(path)
            tmps.append((tmp, path))
            write(str(tmp))
        for tmp, path in tmps:
            os.replace(tmp, path)
        tmps = []
    finally:
        for tmp, _ in tmps:
            tmp.unlink(missing_ok=True)


def _text_writer(text: str) -> Callable[[str], None]:
    return lambda tmp: Path(tmp).write_text(text)


def _fig_writer(fig, path: Path) -> Callable[[str], None]:
    fmt = path.suffix.lstrip(".").lower() or "png"
    return lambda tmp: fig.savefig(tmp, dpi=110, format=fmt)


def _use_progress(flag: Optional[bool]) -> bool:
    return sys.stderr.isatty() if flag is None else flag


class _Bars:
    """rich progress bars on stderr (no-op when disabled)."""

    def __init__(self, enabled: bool):
        self.enabled = enabled
        self.progress = None

    def __enter__(self):
        if self.enabled:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self.progress = Progress(TextColumn("{task.description:<28}"), BarColumn(), MofNCompleteColumn(),
                                     TimeElapsedColumn(), console=Console(stderr=True), transient=True)
            self.progress.__enter__()
        return self

    def __exit__(self, *exc):
        if self.progress is not None:
            self.progress.__exit__(*exc)
        return False

    def add(self, description: str, total: int):
        return self.progress.add_task(description, total=total) if self.progress else None

    def update(self, task, **kw) -> None:
        if self.progress is not None and task is not None:
            self.progress.update(task, **kw)


def _fmt(v: float) -> str:
    return f"{v:.6g}"


# ---------------------------------------------------------------------------------------
# kinetics
# ---------------------------------------------------------------------------------------
@app.command()
def kinetics(
    files: List[Path] = typer.Argument(..., metavar="FILE", help="strain-temperature files to fit (T [degC], strain [-], stress [MPa])"),
    validate: Optional[List[Path]] = typer.Option(None, "--validate", metavar="FILE", help="files only predicted, not fitted (repeatable)"),
    params: str = typer.Option("paper2010", "--params", metavar="BASE", help="base set (named or FILE.toml): D_A, and the rest of FIT.toml"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override NAME=VALUE of the base set (repeatable)"),
    fit_moduli: bool = typer.Option(True, "--fit-dm/--fix-dm", help="fit D_M, or hold it at the base value (D_A is always held: only 1/D_M - 1/D_A is observable)"),
    stress: str = typer.Option("mean", "--stress", metavar="mean|row", help="stress the model sees: mean (per curve) | row"),
    loo: bool = typer.Option(True, "--loo/--no-loo", help="leave-one-level-out check (needs >= 3 fitted files)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FIT.toml", help="fitted parameter file FIT.toml"),
    report: Optional[Path] = typer.Option(None, "--report", metavar="FIT.json", help="fit report FIT.json"),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="FIT.png", help="data vs model figure FIT.png"),
    progress: Optional[bool] = typer.Option(None, "--progress/--no-progress", help="progress bars (default: on a terminal)"),
):
    """Fit the cosine kinetics (A_S0, A_F0, M_S0, M_F0, c_A, c_M, eps_R, D_M) to all FILES at once."""
    from .analysis import kinetics_fit as kf

    cmd = "kinetics"
    if stress not in ("mean", "row"):
        _fail(cmd, f"--stress {stress!r}: must be mean or row")
    _check_out(cmd, "--out", out, (".toml",))
    _check_out(cmd, "--report", report, (".json",))
    _check_out(cmd, "--plot", plot, (".png", ".pdf", ".svg"))
    base_set, base_spec = _base(cmd, params, set_ or [])
    try:
        fitted = [load_strain_curve(f) for f in files]
        validated = [load_strain_curve(f) for f in (validate or [])]
    except DataError as exc:
        _fail(cmd, str(exc))
    t0 = time.perf_counter()
    moduli = ("D_M",) if fit_moduli else ()
    n_loo = len(fitted) if (loo and len(fitted) >= 3) else 0
    with _Bars(_use_progress(progress)) as bars:
        task = bars.add("kinetics: fit all levels", 1 + n_loo)
        fit = kf.fit_kinetics(fitted, base_set, moduli, stress)
        bars.update(task, advance=1)
        loo_res = []
        if n_loo:
            def on_fit(i: int, name: str) -> None:
                bars.update(task, advance=1, description=f"kinetics: left out {name[:16]}")

            loo_res = kf.leave_one_out(fitted, base_set, moduli, stress, on_fit=on_fit)
    wall = time.perf_counter() - t0
    values = {k: v for k, v in fit.params.as_dict().items() if k in fit.fitted}
    problems = kf.plausibility(fit.params)
    at_bound = fit.at_bounds
    names = ", ".join(c.name for c in fitted)
    try:
        toml = parameter_file_text(values, base_spec, "kinetics-fit",
                                   f"smafinger identify kinetics on {names}")
    except ParameterError as exc:
        _fail(cmd, f"the fitted values do not form a valid parameter set: {exc}", 1)
    files_rep = [{"path": c.path, "role": "fitted", "stress_MPa": c.stress_MPa_mean, "n_points": c.n,
                  "rms_strain": fit.rms[c.path]} for c in fitted]
    files_rep += [{"path": c.path, "role": "validated", "stress_MPa": c.stress_MPa_mean, "n_points": c.n,
                   "rms_strain": kf.rms_strain(fit.params, c, stress)} for c in validated]
    rep = {"command": "identify kinetics", "base": params, "overrides": list(set_ or []),
           **fit.to_dict(), "files": files_rep,
           "leave_one_out": [{k: v for k, v in d.items() if k != "params"} for d in loo_res],
           "plausible": not problems, "problems": problems, "at_bounds": at_bound, "wall_s": wall}
    # ---- print
    typer.echo(f"fitted {len(fitted)} curve(s), {fit.n_points} points; stress model: {stress}; "
               f"{fit.nfev} evaluations, {wall:.1f} s")
    units = {"c_A_Pa_per_C": "Pa/degC", "c_M_Pa_per_C": "Pa/degC", "eps_R": "", "D_M_Pa": "Pa", "D_A_Pa": "Pa"}
    for k in fit.fitted:
        typer.echo(f"  {k:<14} = {_fmt(values[k]):>11} +- {fit.stderr[k]:<9.3g} (+- {fit.stderr_ar1[k]:.3g} "
                   f"allowing for correlated residuals) {units.get(k, 'degC')}")
    typer.echo("RMS strain error per curve:")
    for d in files_rep:
        typer.echo(f"  {Path(d['path']).name:<28} {d['stress_MPa']:7.1f} MPa  {d['role']:<9}  "
                   f"{d['rms_strain']:.3e} ({100 * d['rms_strain']:.3f}% strain)")
    if loo_res:
        typer.echo("leave-one-level-out (fit on the others, predict this one):")
        for d in loo_res:
            typer.echo(f"  {Path(d['path']).name:<28} {d['stress_MPa']:7.1f} MPa  predicted  "
                       f"{d['rms_strain']:.3e} ({100 * d['rms_strain']:.3f}% strain)")
    elif loo and len(fitted) < 3:
        typer.echo("leave-one-level-out: skipped (needs at least 3 fitted files)")
    for note in fit.notes:
        typer.echo(f"note: {note}")
    sys.stdout.flush()
    if problems:
        typer.echo("warning: not physically plausible: " + "; ".join(problems), err=True)
    if at_bound:
        typer.echo("warning: at a bound of the search (check the data): " + ", ".join(at_bound), err=True)
    # ---- write
    outputs = []
    if out is not None:
        outputs.append((out, _text_writer(toml)))
    if report is not None:
        outputs.append((report, _text_writer(json.dumps(_jsonable(rep), indent=2) + "\n")))
    if plot is not None:
        outputs.append((plot, _fig_writer(kf.kinetics_figure(fit, fitted, validated, loo_res), plot)))
    _commit(outputs)
    for p_ in (out, report, plot):
        if p_ is not None:
            typer.echo(f"wrote {p_}")


# ---------------------------------------------------------------------------------------
# joint
# ---------------------------------------------------------------------------------------
@app.command()
def joint(
    heating: List[Path] = typer.Option(..., "--heating", metavar="FILE", help="angle-vs-time CSV of a heating experiment (repeatable)"),
    cooling: List[Path] = typer.Option(..., "--cooling", metavar="FILE", help="angle-vs-time CSV of a heat-then-cool experiment (repeatable)"),
    heat_s: Optional[List[float]] = typer.Option(None, "--heat-s", metavar="S", help="heating time [s] before switch-off, one per --cooling file (else its voltage column)"),
    heating_voltage: Optional[float] = typer.Option(None, "--heating-voltage", metavar="V", help="drive [V] of heating files without a voltage column (default: V_H of --params)"),
    cooling_voltage: Optional[float] = typer.Option(None, "--cooling-voltage", metavar="V", help="drive [V] before switch-off for --heat-s (default: V_H of --params)"),
    params: str = typer.Option("paper2010", "--params", metavar="BASE", help="starting/base set (named or FILE.toml)"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override NAME=VALUE of the base set (repeatable)"),
    fit_msf: bool = typer.Option(False, "--fit-msf", help="also fit the static friction moment M_SF (from the heating curves)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FIT.toml", help="fitted parameter file FIT.toml"),
    report: Optional[Path] = typer.Option(None, "--report", metavar="FIT.json", help="fit report FIT.json"),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="FIT.png", help="data vs model figure FIT.png"),
    progress: Optional[bool] = typer.Option(None, "--progress/--no-progress", help="progress bars (default: on a terminal)"),
):
    """Fit h0, h2, C_DF of the heating and of the cooling phase to joint angle curves (Fig. 9)."""
    from .analysis import joint_fit as jf

    cmd = "joint"
    _check_out(cmd, "--out", out, (".toml",))
    _check_out(cmd, "--report", report, (".json",))
    _check_out(cmd, "--plot", plot, (".png", ".pdf", ".svg"))
    base_set, base_spec = _base(cmd, params, set_ or [])
    vh = base_set.V_H_V if heating_voltage is None else heating_voltage
    vc = base_set.V_H_V if cooling_voltage is None else cooling_voltage
    for opt, v in (("--heating-voltage", vh), ("--cooling-voltage", vc)):
        if not (math.isfinite(v) and 0.0 < v <= 100.0):
            _fail(cmd, f"{opt} {v:g}: must be in (0, 100] V")
    heat_s = list(heat_s or [])
    if heat_s and len(heat_s) != len(cooling):
        _fail(cmd, f"--heat-s given {len(heat_s)} time(s) for {len(cooling)} --cooling file(s): give one "
                   f"per cooling file, in the same order, or none (voltage columns)")
    try:
        h_curves = [load_angle_curve(f) for f in heating]
        c_curves = [load_angle_curve(f) for f in cooling]
        h_exps = [(c, jf.heating_program(c, vh)) for c in h_curves]
        c_exps = [(c, jf.cooling_program(c, vc, heat_s[i] if heat_s else None)) for i, c in enumerate(c_curves)]
    except _INPUT_ERRORS as exc:
        _fail(cmd, str(exc))
    t0 = time.perf_counter()
    budget = jf.phase_budget(fit_msf)
    with _Bars(_use_progress(progress)) as bars:
        tasks = {"heating": bars.add("joint: heating fit", budget), "cooling": bars.add("joint: cooling fit", budget)}

        def on_eval(phase: str, n: int) -> None:
            bars.update(tasks[phase], completed=min(n, budget - 1))

        try:
            fit = jf.fit_joint(h_exps, c_exps, base_set, fit_msf=fit_msf, on_eval=on_eval)
        except ValueError as exc:
            _fail(cmd, str(exc))
        except SimulationError as exc:
            _fail(cmd, f"simulation failed: {exc}", 1)
        for t in tasks.values():
            bars.update(t, completed=budget)
    wall = time.perf_counter() - t0
    values = fit.values
    names = ", ".join(Path(c.path).name for c in h_curves + c_curves)
    try:
        toml = parameter_file_text(values, base_spec, "joint-fit", f"smafinger identify joint on {names}")
    except ParameterError as exc:
        _fail(cmd, f"the fitted values do not form a valid parameter set: {exc}", 1)
    rep = {"command": "identify joint", "base": params, "overrides": list(set_ or []), **fit.to_dict(),
           "wall_s": wall}
    typer.echo(f"fitted {len(h_curves)} heating and {len(c_curves)} cooling curve(s) in {wall:.1f} s "
               f"({fit.heating.nfev + fit.cooling.nfev} simulations)")
    for pf in (fit.heating, fit.cooling):
        typer.echo(f"{pf.phase}: RMS {pf.rms_deg:.4f} deg (start {pf.rms_start_deg:.3f} deg)")
        for k in pf.fields:
            typer.echo(f"  {k:<18} = {_fmt(pf.values[k]):>11} +- {pf.stderr[k]:<9.3g} "
                       f"({100 * pf.rel_stderr[k]:.2g}%), start {_fmt(pf.start[k])}")
        for d in pf.curves:
            typer.echo(f"  {Path(d['path']).name:<28} program {d['program']:<18} RMS {d['rms_deg']:.4f} deg")
    sys.stdout.flush()
    for w in fit.warnings:
        typer.echo(f"warning: {w}", err=True)
    outputs = []
    if out is not None:
        outputs.append((out, _text_writer(toml)))
    if report is not None:
        outputs.append((report, _text_writer(json.dumps(_jsonable(rep), indent=2) + "\n")))
    if plot is not None:
        outputs.append((plot, _fig_writer(jf.joint_figure(fit, base_set), plot)))
    _commit(outputs)
    for p_ in (out, report, plot):
        if p_ is not None:
            typer.echo(f"wrote {p_}")


def _jsonable(x):
    """Plain JSON types (numpy scalars to float, inf/nan to null)."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return x
    if isinstance(x, int):
        return x
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return v if math.isfinite(v) else None


# identify actuator (issue 12): fit a bench actuator to recorded runs, predict held-out ones
from .cli_identify_actuator import actuator as _actuator  # noqa: E402

app.command("actuator")(_actuator)
