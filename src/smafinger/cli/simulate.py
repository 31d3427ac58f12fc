"""``smafinger simulate``: one run, its metrics printed, its outputs written together."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import List, Optional

import typer

from .choices import (DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_OUTPUT_S, DEFAULT_PWM, DEFAULT_TOL_DEG, DEFAULT_TOL_M,
                      ENGINE_ENV, LONG_STEP_DT_S, LONG_STEP_METHOD, LONG_STEP_PWM, LONG_STEP_STIFF_METHOD)
from .common import Engine, Method, Pwm, Strategy, given, load_params, progress_display, progress_option, refuse
from .errors import NOTHING_WRITTEN, UsageError, command, reading_input

#: the default of --dt, --method and --pwm (engine.numerics), told once, under --method
NUMERICS_HELP = (f"[default, with none of --dt/--method/--pwm given: a long step, {LONG_STEP_DT_S:g} s, "
                 f"{LONG_STEP_PWM}, where validated (the memory rule): "
                 f"{LONG_STEP_METHOD} for the finger joint (its rate law with per-metre heating and the paper's "
                 f"PID, sliding-mode or open loop; the algebraic law in open loop; not the linear rig, whose "
                 f"{LONG_STEP_STIFF_METHOD} long step damps the slider's momentum after a drive change); a PWM period "
                 f"of 5 ms or less, and the transformation band crossed in 20 long steps or more; "
                 f"else for the finger joint with per-metre heating (any hysteresis rule, PWM period or stress law; "
                 f"open loop, pid, sliding-mode or rapid-heating): {LONG_STEP_METHOD}, {LONG_STEP_DT_S:g} s, "
                 f"{DEFAULT_PWM} (sub-steps at every PWM edge); "
                 f"otherwise, for --scenario, and for any of the three not given: {DEFAULT_METHOD}, "
                 f"{DEFAULT_DT_S:g} s (1 ms / n, shorter, on a slider whose wire-slider mode turns over 1 rad in "
                 f"that, or where the damping over the inertia is over 2,000 1/s), {DEFAULT_PWM}; docs/speed.md]")

#: options that define the run (refused with --from; --scenario takes some of them)
RUN_OPTIONS = ("params", "set_", "scenario", "strategy", "profile", "voltage", "duty", "current", "t_end", "dt",
               "method", "pwm", "output_interval", "tol_deg", "tol_m", "hold_s")
#: options a scenario defines and the command line cannot change
NOT_WITH_SCENARIO = ("params", "voltage", "duty", "current", "tol_m")


@command(interrupted=NOTHING_WRITTEN)
def simulate(
    ctx: typer.Context,
    params: str = typer.Option("paper2010", "--params", metavar="NAME|FILE.toml", help="named set or parameter file"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override a parameter (repeatable)"),
    scenario: Optional[str] = typer.Option(None, "--scenario", metavar="NAME",
                                           help="a named scenario (see 'smafinger scenarios'); --set, --strategy, "
                                                "--profile, --t-end and the run settings change it"),
    from_: Optional[Path] = typer.Option(None, "--from", metavar="FILE",
                                         help="re-run exactly the run a summary .json, a .csv (its .provenance.json), "
                                              ".parquet or .mat records"),
    strategy: Strategy = typer.Option("cooperative", "--strategy", help="control strategy"),
    profile: Optional[str] = typer.Option(
        None, "--profile", metavar="T:TARGET[:ENABLE],...",
        help='targets (s; deg for the joint, m for a linear actuator; T may be "reach"; ENABLE auto, none, both '
             'or a wire)'),
    voltage: Optional[str] = typer.Option(None, "--voltage", metavar="T:V_1[:V_2],...",
                                          help="open-loop program [V], one value per wire"),
    duty: Optional[str] = typer.Option(None, "--duty", metavar="T:D_1[:D_2],...",
                                       help="open-loop program: duty 0-1 of the supply V_H"),
    current: Optional[str] = typer.Option(None, "--current", metavar="T:I_1[:I_2],...", help="open-loop program [A]"),
    t_end: float = typer.Option(20.0, "--t-end", metavar="S", help="simulated time [s]"),
    dt: Optional[float] = typer.Option(None, "--dt", metavar="S", help="integration step [s] [default: see --method]"),
    method: Optional[Method] = typer.Option(None, "--method", help="integrator (authors-ode4: the authors' Simulink "
                                                                   f"solver, fixed 1 ms (shorter on a stiff slider or a heavily damped joint), PWM read at its stages) {NUMERICS_HELP}"),
    pwm: Optional[Pwm] = typer.Option(None, "--pwm", help="PWM drive: resolved at its edges (exact) or its period-"
                                                          "averaged power (averaged: long steps) [default: see --method]"),
    output_interval: float = typer.Option(DEFAULT_OUTPUT_S, "--output-interval", metavar="S", help="output sampling [s]"),
    tol_deg: float = typer.Option(DEFAULT_TOL_DEG, "--tol-deg", metavar="DEG",
                                  help="target tolerance of the joint [deg]"),
    tol_m: float = typer.Option(DEFAULT_TOL_M, "--tol-m", metavar="M", help="target tolerance of a linear actuator [m]"),
    hold_s: float = typer.Option(0.5, "--hold-s", metavar="S", help="time a target must hold within tolerance [s]"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FILE",
                                       help="signals to FILE.csv (+ FILE.provenance.json), .parquet or .mat"),
    summary: Optional[Path] = typer.Option(None, "--summary", metavar="FILE.json", help="metrics and provenance"),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="FILE", help="figure to FILE.png, .pdf or .svg"),
    check_step: Optional[bool] = typer.Option(
        None, "--check-step/--no-check-step",
        help="run it again at half the step and compare the position: warn if the error estimated from the "
             "difference (about twice it) is over the accuracy budget the defaults were validated against "
             "(docs/cli.md) "
             "[default: on for the linear rig, and for a finger-joint set changed from a named one (--set, a file) "
             "outside a named scenario; off for the named joint sets and the scenarios, where the defaults were "
             "validated]"),
    progress: Optional[bool] = progress_option(),
    engine: Optional[Engine] = typer.Option(
        None, "--engine", help="compiled: the numba kernel (compiled first if not cached); interpreted: the same "
                               "kernel as plain Python; auto: compiled if cached, else a short run interpreted while "
                               f"the kernel compiles in the background [default: ${ENGINE_ENV}, else auto]"),
):
    """Simulate an SMA actuator (the finger joint or a linear bias-spring rig) and report the metrics."""
    from ..engine.interpreted import engine_setting
    from ..engine.run import run_spec
    from ..export import add_plot, add_signals, add_summary
    from ..files import Outputs
    from ..plausibility import hinted

    _check_outputs(out, summary, plot)
    try:
        setting = engine_setting(engine)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    spec, extra = _spec(ctx, params, set_, scenario, from_, strategy, profile, voltage, duty, current, t_end, dt,
                        method, pwm, output_interval, tol_deg, tol_m, hold_s)
    checking = _check_choice(check_step, spec, extra)
    with progress_display(progress) as display:
        result = hinted(spec, lambda: run_spec(spec, progress=display, engine=setting))
        if checking:  # its failure says it is the check's (a shorter step is no advice there)
            result = _step_checked(result, setting, display)
    outputs = Outputs()
    if out is not None:
        add_signals(outputs, result, out, "--out", **extra)
    if summary is not None:
        add_summary(outputs, result, summary, "--summary", **extra)
    if plot is not None:
        add_plot(outputs, result, plot, "--plot", title=extra.get("scenario"))
    outputs.commit()
    from .show import print_run

    print_run(result)
    from ..engine.compiled import INTERPRETED

    if result.engine == "interpreted":
        print(f"smafinger: note: this run was interpreted ({result.wall_s:.1f} s; the same equations as the compiled "
              "kernel, equal to rounding)" + ("" if setting != "auto" or INTERPRETED else
                                             ": the compiled kernel was not in numba's cache, and is being compiled "
                                             "in the background for the runs that follow"), file=sys.stderr)


def _step_checked(result, setting: str, display):
    """``result`` with its step check on the engine :func:`~smafinger.step_check.check_engine`
    chooses, or as it is, with a note, where that would take long interpreted."""
    from ..step_check import check_engine, with_step_check

    check_with = check_engine(result, setting)
    if check_with is not None:
        return with_step_check(result, check_with, progress=display)
    print("smafinger: note: the step was not checked: this run was interpreted while the kernel compiles, and the "
          "same run at half the step would take long interpreted; run it again once the kernel is compiled",
          file=sys.stderr)
    return result


def _check_choice(flag: Optional[bool], spec, extra: dict) -> bool:
    """Whether to check the run's step (:mod:`smafinger.step_check`): ``--check-step`` or
    ``--no-check-step`` (recorded in ``extra``, the run's provenance), else what a replayed run
    recorded, else the default (on a slider). Asked for where the step has no shorter one: a
    usage error before the run; by default there: a note, and no check."""
    from ..step_check import checked_by_default, uncheckable

    recorded = extra.get("check_step")
    if flag is not None:
        extra["check_step"] = "on" if flag else "off"  # text: every output format holds it
        want = flag
    elif recorded in ("on", "off"):
        want = recorded == "on"
    else:  # a named scenario as registered was validated (its set may differ from the named one)
        want = checked_by_default(spec.params, validated=_as_registered(spec, extra))
    why = uncheckable(spec) if want else None
    if why is not None and flag:
        raise UsageError(f"--check-step: {why}")
    if why is not None:
        print(f"smafinger: note: the step was not checked: {why}", file=sys.stderr)
        return False
    return want


def _as_registered(spec, extra: dict) -> bool:
    """Whether ``spec`` is a named scenario's run as registered: no change given, or changes that
    leave the same run (its own numerics repeated, ``--dt 0.001``; found by review)."""
    if "scenario" not in extra:
        return False
    if "scenario_changes" not in extra:
        return True
    from .. import scenarios

    return spec == scenarios.get(extra["scenario"]).spec()


def _check_outputs(out: Path | None, summary: Path | None, plot: Path | None) -> None:
    """Refuse bad output names before anything runs."""
    from ..export import PLOT_SUFFIXES, SIGNAL_FORMATS, check_suffix, sidecar_path
    from ..files import check_outputs

    targets = []
    for path, what, allowed in ((out, "--out", SIGNAL_FORMATS), (summary, "--summary", (".json",)),
                                (plot, "--plot", PLOT_SUFFIXES)):
        if path is not None:
            targets.append((path, what))
            if check_suffix(path, allowed, what) == ".csv":
                targets.append((sidecar_path(path), f"{what} (its provenance sidecar)"))
    check_outputs(targets)


def _spec(ctx, params, set_, scenario, from_, strategy, profile, voltage, duty, current, t_end, dt, method, pwm,
          output_interval, tol_deg, tol_m, hold_s):
    """(the run spec, what the outputs record beside it) from the options."""
    from ..engine.run import make_spec

    if from_ is not None:
        from ..export import read_provenance
        from ..provenance import FILE_KEYS, spec_from_provenance

        refuse(ctx, RUN_OPTIONS, f"with --from {from_}: it re-runs the run recorded there")
        record = read_provenance(from_)
        # what the first run recorded beside its definition (a scenario's name), as it did; not what
        # described its file's samples (FILE_KEYS): the re-run writes every sample
        same = {k: v for k, v in record.items() if k not in ("smafinger_version", "run", "run_sha256", *FILE_KEYS)}
        return spec_from_provenance(record, f"--from {from_}"), same
    programs = [(k, v) for k, v in (("voltage", voltage), ("duty", duty), ("current", current)) if v is not None]
    if len(programs) > 1:
        raise UsageError(f"give one drive program, not {' and '.join('--' + k for k, _ in programs)}")
    if scenario is not None:
        from .. import scenarios

        refuse(ctx, NOT_WITH_SCENARIO, f"with --scenario {scenario} (it sets them; change parameters with --set)")
        changed = set(given(ctx, "strategy", "profile", "t_end", "tol_deg", "hold_s"))

        def option(value, flag):  # what the command line changes; None: the scenario's own
            return value if flag in changed else None

        with reading_input():
            spec = scenarios.get(scenario).spec(
                overrides=set_ or [], dt_s=dt, method=method, pwm=pwm, output_interval_s=output_interval,
                tol_deg=option(tol_deg, "--tol-deg"), hold_s=option(hold_s, "--hold-s"),
                strategy=option(strategy, "--strategy"), profile=option(profile, "--profile"),
                t_end_s=option(t_end, "--t-end"))
        # the name stands for the scenario's own run: a changed one says what changed (found by review)
        runs_flags = set(given(ctx, "strategy", "profile", "t_end", "tol_deg", "hold_s", "dt", "method", "pwm"))
        changes = [f"--set {a}" for a in set_ or []] + [
            f"{flag} {value}" for flag, value in (("--strategy", strategy), ("--profile", profile),
                                                  ("--t-end", t_end), ("--tol-deg", tol_deg), ("--hold-s", hold_s),
                                                  ("--dt", dt), ("--method", method), ("--pwm", pwm))
            if flag in runs_flags]
        # one string: every output format holds it (a .mat file's provenance takes no list of strings)
        return spec, {"scenario": scenario, **({"scenario_changes": " ".join(changes)} if changes else {})}
    kind, program = programs[0] if programs else ("voltage", None)
    p = load_params(params, set_)
    with reading_input():
        return make_spec(p, strategy, profile, program, t_end, dt, method, output_interval, tol_deg, hold_s,
                         tol_m=tol_m, drive=kind, pwm=pwm), {}
