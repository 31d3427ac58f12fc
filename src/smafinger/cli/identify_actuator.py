"""``smafinger identify actuator``: fit an actuator's set to bench runs, predict held-out runs.

The command function :func:`actuator` is mounted under ``smafinger identify``::

    identify_app.command("actuator")(actuator)

Bad input (files, mappings, options, parameter files) prints one line and exits with status 2;
a fit or simulation that fails exits with status 1. Nothing is written unless everything
succeeded: every output goes to a temporary file first, then all are renamed into place.
Method, options and report: ``docs/identification.md``.
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

from .choices import FIT_BUDGET, FIT_MAX_NFEV, FIT_SEED
from .common import repeated_file

CMD = "smafinger identify actuator"
#: separates a run's file from its own mapping: RUN.mat::duty=u,position_m=x_mm*1e-3
RUN_MAP = "::"


class Usage(Exception):
    """Bad input: one line, exit status 2."""


def _fail(msg: str, code: int) -> None:
    typer.echo(f"{CMD}: error: {str(msg).splitlines()[0] if str(msg) else 'error'}", err=True)
    raise typer.Exit(code)


def actuator(
    params: str = typer.Option(..., "--params", metavar="RIG", help="the rig's set: a named set or RIG.toml (the start of the fit)"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override a field of --params (repeatable)"),
    fit: Optional[List[str]] = typer.Option(None, "--fit", metavar="RUN", help="open-loop run to fit: .csv, .parquet or .mat, optionally RUN::NAME=SOURCE,... (repeatable)"),
    validate: Optional[List[str]] = typer.Option(None, "--validate", metavar="RUN", help="open-loop run only predicted (repeatable)"),
    replay: Optional[List[str]] = typer.Option(None, "--replay", metavar="RUN", help="closed-loop run: its reference drives the rig's PID, then compared (repeatable)"),
    map_: Optional[List[str]] = typer.Option(None, "--map", metavar="NAME=SOURCE[*F]", help="which column/variable is which signal in every run, e.g. position_m=x_mm*1e-3 (repeatable)"),
    reference: Optional[str] = typer.Option(None, "--reference", metavar="SOURCE[*F]", help="reference column of --replay files (default position_ref_m or theta_ref_deg)"),
    gains: Optional[str] = typer.Option(None, "--gains", metavar="KP:KV:KI", help="the rig's PID gains in duty (0-1) per m [s/m, 1/(m s)] or per rad (default: the set's)"),
    duty_max: float = typer.Option(1.0, "--duty-max", metavar="D", help="the rig's duty clamp (fraction of V_H)"),
    free: Optional[List[str]] = typer.Option(None, "--free", metavar="NAME[:LO:HI]", help="a field to fit, with bounds; A+B ties fields (repeatable; default per mechanism)"),
    wire: Optional[str] = typer.Option(None, "--wire", metavar="NAME", help="the wire the recorded input drives (default: the first)"),
    offset: str = typer.Option("per-run", "--offset", metavar="per-run|none", help="a sensor offset per run (fitted, or measured before the drive on held-out runs), or none"),
    budget: int = typer.Option(FIT_BUDGET, "--budget", metavar="N", help="candidate sets the global stage (CMA-ES) may try; 0 skips it"),
    max_nfev: int = typer.Option(FIT_MAX_NFEV, "--max-nfev", metavar="N", help="iterations of the least-squares stage"),
    seed: int = typer.Option(FIT_SEED, "--seed", metavar="N", help="seed of the global stage"),
    workers: Optional[int] = typer.Option(None, "--workers", metavar="N", help="worker processes (default: every core; 1: this process)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FIT.toml", help="fitted parameter file (needs --fit)"),
    report: Optional[Path] = typer.Option(None, "--report", metavar="REPORT.json", help="JSON report"),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="DIR", help="a figure per run, measured against predicted, into DIR"),
    progress: Optional[bool] = typer.Option(None, "--progress/--no-progress", help="simulation count on stderr (default: on a terminal)"),
):
    """Fit an SMA actuator's parameters to bench runs at once; predict held-out and closed-loop runs."""
    from ..analysis.actuator_fit import FitError
    from ..engine.pools import BatchError
    from ..engine.run import SimulationError
    from ..parameters import ParameterError
    from ..profiles import ProfileError
    from ..recordings import RecordingError

    t0 = time.perf_counter()
    try:
        setup = _setup(params, set_ or [], fit or [], validate or [], replay or [], map_ or [], reference, gains,
                       duty_max, free or [], wire, offset, budget, max_nfev, seed, workers, out, report, plot)
    except (Usage, RecordingError, ParameterError, ProfileError, ValueError) as exc:
        _fail(str(exc), 2)
    try:
        result = _compute(setup, _use_progress(progress))
    except (FitError, SimulationError, BatchError) as exc:
        _fail(str(exc), 1)
    outputs, rep = _outputs(setup, result, time.perf_counter() - t0)
    _commit(outputs, plot)  # before anything is printed: a closed stdout must not lose the fit
    _print(setup, result)
    for path in (out, report):
        if path is not None:
            typer.echo(f"wrote {path}")
    if plot is not None:
        typer.echo(f"wrote {len(result['predictions'])} figure(s) to {plot}")


def _setup(params, overrides, fit, validate, replay, maps, reference, gains, duty_max, free, wire, offset, budget,
           max_nfev, seed, workers, out, report, plot) -> dict:
    """Everything checked before any simulation: options, outputs, the set, the runs."""
    from ..analysis import actuator_report as ar
    from ..analysis.actuator_fit import FitSettings
    from ..analysis.bench_runs import load_closed_loop, load_open_loop
    from ..analysis.data import same_data
    from ..analysis.free_params import FreeBox, parse_free
    from ..engine.numerics import reference_dt_within
    from ..parameters import REGISTRY, resolve
    from ..recordings import parse_map_options

    if not (fit or validate or replay):
        raise Usage("no run given: use --fit, --validate or --replay RUN (repeatable)")
    if offset not in ar.OFFSET_POLICIES:
        raise Usage(f"--offset {offset!r}: must be one of {', '.join(ar.OFFSET_POLICIES)}")
    for opt, value, lo in (("--budget", budget, 0), ("--max-nfev", max_nfev, 1), ("--workers", workers, 1)):
        if value is not None and value < lo:
            raise Usage(f"{opt} {value}: must be >= {lo}")
    if not fit and (free or out is not None):
        raise Usage(f"{'--free' if free else '--out'} needs runs to fit (--fit RUN)")
    replay_only = [o for o, given in (("--gains", gains is not None), ("--duty-max", duty_max != 1.0),
                                      ("--reference", reference is not None)) if given]
    if replay_only and not replay:
        raise Usage(f"{replay_only[0]} is for closed-loop runs: give them with --replay RUN")
    _check_path("--out", out, (".toml",))
    _check_path("--report", report, (".json",))
    if plot is not None and (plot.exists() and not plot.is_dir() or not plot.parent.exists()):
        raise Usage(f"--plot {plot}: must be a directory (its parent must exist)")
    if (twice := repeated_file(_split_run(a)[0] for a in fit + validate + replay)) is not None:
        raise Usage(twice)
    p = resolve(params).with_overrides(overrides)
    parse_map_options(maps)  # refuse a bad --map before reading any file
    controller = _controller(gains, duty_max) if replay else None
    box = FreeBox(p, parse_free(p, free)) if fit else None
    # RK4's step: 1 ms, shorter on a stiff slider, for the stiffest set the fit may try (engine.numerics)
    dt_s = reference_dt_within(p, {name: (f.lo, f.hi) for f in box.free for name in f.fields} if box else {})
    runs = [load_open_loop(*_run_map(a, maps), "fit", p, wire=wire, dt_s=dt_s) for a in fit]
    runs += [load_open_loop(*_run_map(a, maps), "validate", p, wire=wire, dt_s=dt_s) for a in validate]
    runs += [load_closed_loop(*_run_map(a, maps), p, controller, reference=reference, offset=offset == "per-run",
                              dt_s=dt_s) for a in replay]
    if (copy := same_data((r.file, (r.recording.input.t_s, r.recording.input.values, r.recording.output.t_s,
                                    r.recording.output.values)) for r in runs)) is not None:
        raise Usage(copy)
    for run in runs if offset == "per-run" else []:
        if run.role == "validate":  # its offset is measured on its baseline (a fitted run's is fitted)
            run.check_baseline()
    settings = FitSettings(budget=budget, max_nfev=max_nfev, seed=seed, fit_offsets=offset == "per-run", dt_s=dt_s)
    base = params if (params in REGISTRY and not overrides) else p
    return dict(params=params, overrides=overrides, p=p, base=base, runs=runs, box=box, settings=settings,
                controller=controller, offset=offset, workers=workers, out=out, report=report, plot=plot)


def _split_run(arg: str) -> tuple[str, list[str]]:
    """``RUN`` or ``RUN::NAME=SOURCE,...`` -> (file, its own mapping options)."""
    path, sep, maps = arg.partition(RUN_MAP)
    if not path:
        raise Usage(f"{arg!r}: no file name before {RUN_MAP!r}")
    return path, [m for m in maps.split(",") if m.strip()] if sep else []


def _run_map(arg: str, maps: list[str]):
    """(file, mapping): the run's own ``::`` entries override ``--map`` entries of the same signal."""
    from ..recordings import parse_map_options

    path, own = _split_run(arg)
    names = {m.partition("=")[0].strip() for m in own}
    return path, parse_map_options([m for m in maps if m.partition("=")[0].strip() not in names] + own)


def _check_path(opt: str, path: Optional[Path], suffixes: tuple[str, ...]) -> None:
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        raise Usage(f"{opt} {path}: the file name must end in {' or '.join(suffixes)}")
    if not path.parent.exists():
        raise Usage(f"{opt} {path}: directory {path.parent} does not exist")
    if path.is_dir():
        raise Usage(f"{opt} {path}: is a directory")


def _controller(gains: Optional[str], duty_max: float) -> RigController:
    from ..analysis.bench_runs import RigController

    if gains is None:
        return RigController(duty_max=duty_max)
    parts = gains.split(":")
    try:
        values = [float(x) for x in parts]
    except ValueError:
        raise Usage(f"--gains {gains!r}: expected three numbers KP:KV:KI") from None
    if len(values) != 3:
        raise Usage(f"--gains {gains!r}: expected three numbers KP:KV:KI, got {len(values)}")
    return RigController(*values, duty_max=duty_max)


def _use_progress(flag: Optional[bool]) -> bool:
    return sys.stderr.isatty() if flag is None else flag


def _compute(setup: dict, show: bool) -> dict:
    """The fit (if any runs are fitted) and every run's prediction with the resulting set."""
    from rich.console import Console
    from rich.progress import Progress, TextColumn, TimeElapsedColumn

    from ..analysis import actuator_report as ar
    from ..analysis.actuator_fit import fit_actuator
    from ..engine.batch import make_pool

    runs, box, s = setup["runs"], setup["box"], setup["settings"]
    fit_runs = [r for r in runs if r.role == "fit"]
    bar = Progress(TextColumn("{task.description}"), TimeElapsedColumn(), console=Console(stderr=True),
                   transient=True, disable=not show)
    with bar, make_pool(setup["workers"]) as pool:
        task = bar.add_task("identify actuator: starting")

        def on_sim(n: int) -> None:
            bar.update(task, description=f"identify actuator: {n} simulations")

        fit = fit_actuator(fit_runs, box, pool, s, on_sim) if fit_runs else None
        p = fit.params if fit else setup["p"]
        offsets = {f: (fit.offsets[f], fit.offset_stderr[f]) for f in fit.offsets} if fit else {}
        predictions = ar.predict_runs(runs, p, pool, offsets, setup["offset"], s.dt_s)
    steps = ar.step_notes(predictions, p, fit is not None)  # whether the model converged at the step
    if fit is not None:  # whether the fit reaches the noise: warned and in the report's notes
        fit.notes.extend(ar.misfit_notes(predictions, p) + steps)
    return {"fit": fit, "p": p, "predictions": predictions, "step_notes": steps}


def _outputs(setup: dict, result: dict, wall_s: float) -> tuple[list[tuple[Path, Callable[[str], None]]], dict]:
    """(path, writer) of every output, and the report."""
    from ..analysis import actuator_report as ar
    from ..analysis.data import parameter_file_text
    from ..parameters import ParameterError

    p, fit, preds = result["p"], result["fit"], result["predictions"]
    names = ar.figure_names(preds)
    plot = setup["plot"]
    figures = {f: str(plot / n) for f, n in names.items()} if plot is not None else {}
    rep = {"command": "identify actuator", "params": setup["params"], "overrides": setup["overrides"],
           "mechanism": p.mechanism, "output": ar.output_si_name(p), "unit": ar.unit_suffix(p),
           "offset_policy": setup["offset"], "files": ar.files_report(preds, p, figures),
           "summary": ar.role_summary(preds, p), "fit": fit.to_dict() if fit else None,
           "controller": None if setup["controller"] is None else vars(setup["controller"]),
           "parameter_file": None if setup["out"] is None else str(setup["out"]),
           "step_notes": result["step_notes"], "wall_s": wall_s}
    outputs: list[tuple[Path, Callable[[str], None]]] = []
    if setup["out"] is not None:
        files = ", ".join(Path(r.file).name for r in setup["runs"] if r.role == "fit")
        try:
            text = parameter_file_text(setup["box"].fields(fit.values), setup["base"], "actuator-fit",
                                       f"smafinger identify actuator on {files}")
        except ParameterError as exc:
            _fail(f"the fitted values do not form a valid parameter set: {exc}", 1)
        outputs.append((setup["out"], lambda tmp: Path(tmp).write_text(text)))
    if setup["report"] is not None:
        text_rep = json.dumps(_jsonable(rep), indent=2) + "\n"
        outputs.append((setup["report"], lambda tmp: Path(tmp).write_text(text_rep)))
    for pr in preds if plot is not None else []:
        outputs.append((plot / names[pr.run.file], _figure_writer(pr, p)))
    return outputs, rep


def _figure_writer(pr, p) -> Callable[[str], None]:
    def write(tmp: str) -> None:
        import matplotlib.pyplot as plt

        from ..analysis import actuator_report as ar

        fig = ar.run_figure(pr, p)
        try:
            fig.savefig(tmp, dpi=110, format="png")
        finally:
            plt.close(fig)

    return write


def _commit(outputs: list[tuple[Path, Callable[[str], None]]], plot: Optional[Path]) -> None:
    """Write every output to a temporary file beside it, then rename all into place."""
    from ..files import temp_path

    made_dir = plot is not None and not plot.exists()
    if made_dir:
        plot.mkdir()
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
        if made_dir and tmps and not any(plot.iterdir()):
            plot.rmdir()


def _print(setup: dict, result: dict) -> None:
    from ..analysis import actuator_report as ar

    p, fit, preds = result["p"], result["fit"], result["predictions"]
    factor, unit, _ = ar.DISPLAY[ar.output_si_name(p)]
    if fit is not None:
        n_fit = sum(r.n_samples for r in setup["runs"] if r.role == "fit")
        typer.echo(f"fitted {len(fit.offsets)} run(s) ({n_fit} samples), {len(fit.free)} parameter(s): "
                   f"{fit.n_simulations} simulations in {fit.wall_s:.1f} s; RMS {factor * fit.rms_start:.4g} -> "
                   f"{factor * fit.rms:.4g} {unit}")
        for f in fit.free:
            typer.echo(f"  {f.name:<24} = {fit.values[f.name]:<11.6g} +- {fit.stderr[f.name]:<9.3g} "
                       f"(independent residuals: +- {fit.stderr_white[f.name]:.3g}; start {fit.start[f.name]:.6g}, "
                       f"bounds {f.lo:g}..{f.hi:g})")
    typer.echo(f"{'run':<28} {'role':<9} {'mode':<12} {'RMS':>10} {'max':>10} {'offset':>10}  [{unit}]")
    for pr in preds:
        st = pr.stats()
        rms = "failed" if st["rms"] is None else f"{factor * st['rms']:.4g}"
        mx = "" if st["max_abs"] is None else f"{factor * st['max_abs']:.4g}"
        typer.echo(f"{Path(pr.run.file).name[:28]:<28} {pr.run.role:<9} {pr.run.mode:<12} {rms:>10} {mx:>10} "
                   f"{factor * pr.offset:>10.4g}  ({pr.offset_method})")
    sys.stdout.flush()
    for note in (fit.notes + [f"at a bound: {', '.join(fit.at_bounds)}"] * bool(fit.at_bounds)) if fit else \
            result["step_notes"]:
        typer.echo(f"warning: {note}", err=True)
    for pr in preds:
        if pr.error:
            typer.echo(f"warning: {pr.run.file}: simulation failed: {pr.error}", err=True)


def _jsonable(x):
    """Plain JSON types (numpy scalars to float, inf/nan to null)."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, bool) or x is None or isinstance(x, (str, int)):
        return x
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return v if math.isfinite(v) else None
