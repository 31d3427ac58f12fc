"""Command-line interface: ``smafinger simulate | reproduce | identify | sweep | params``."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import List, Optional

import typer

from .engine.run import (
    DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_OUTPUT_S, DEFAULT_TOL_M, SimulationError, make_spec, run_spec,
)
from .parameters import ParameterError, names, resolve
from .profiles import ProfileError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="Simulate, control and identify SMA tendon-driven finger joints (Gilardi et al. 2010).",
)

USAGE_ERRORS = (ParameterError, ProfileError, ValueError, FileNotFoundError)


class UsageProblem(Exception):
    """Bad input from the user: one line, exit status 2."""


def _load_params(params: str, overrides: list[str]):
    return resolve(params).with_overrides(overrides or [])


@app.command()
def simulate(
    params: str = typer.Option("paper2010", "--params", help="named set or FILE.toml"),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="override NAME=VALUE (repeatable)"),
    scenario: Optional[str] = typer.Option(None, "--scenario", help="a named scenario (see 'smafinger scenarios')"),
    strategy: str = typer.Option("cooperative", "--strategy", help="open-loop | independent | cooperative"),
    profile: Optional[str] = typer.Option(
        None, "--profile", help='targets "T:TARGET[:ENABLE],..." (s; deg for the joint, m for a linear actuator; T may be "reach")'),
    voltage: Optional[str] = typer.Option(None, "--voltage", help='open-loop program "T:V_1[:V_2],..." [V], one value per wire'),
    duty: Optional[str] = typer.Option(None, "--duty", help='open-loop program "T:D_1[:D_2],...": duty 0-1 of the supply V_H'),
    current: Optional[str] = typer.Option(None, "--current", help='open-loop program "T:I_1[:I_2],..." [A]'),
    t_end: float = typer.Option(20.0, "--t-end", help="simulated time [s]"),
    dt: float = typer.Option(DEFAULT_DT_S, "--dt", help="integration step [s]"),
    method: str = typer.Option(DEFAULT_METHOD, "--method", help="rk4 | euler"),
    output_interval: float = typer.Option(DEFAULT_OUTPUT_S, "--output-interval", help="output sampling [s]"),
    tol_deg: float = typer.Option(0.5, "--tol-deg", help="target tolerance of the joint [deg]"),
    tol_m: float = typer.Option(DEFAULT_TOL_M, "--tol-m", help="target tolerance of a linear actuator [m]"),
    hold_s: float = typer.Option(0.5, "--hold-s", help="time the joint must stay within tolerance [s]"),
    out: Optional[Path] = typer.Option(None, "--out", help="signals to FILE.csv or FILE.parquet"),
    summary: Optional[Path] = typer.Option(None, "--summary", help="metrics to FILE.json"),
    plot: Optional[Path] = typer.Option(None, "--plot", help="figure to FILE.png"),
    progress: Optional[bool] = typer.Option(None, "--progress/--no-progress", help="progress bar (default: on a terminal)"),
):
    """Simulate an SMA actuator (the finger joint or a linear bias-spring rig) and report the metrics."""
    if out is not None and out.suffix.lower() not in (".csv", ".parquet", ".pq"):
        raise UsageProblem(f"--out {out}: the file must end in .csv or .parquet")
    for opt, path in (("--out", out), ("--summary", summary), ("--plot", plot)):
        if path is not None and not path.parent.exists():
            raise UsageProblem(f"{opt} {path}: directory {path.parent} does not exist")
    if scenario is not None:
        from . import scenarios

        spec = scenarios.get(scenario).spec(overrides=set_ or [], dt_s=dt, method=method,
                                            output_interval_s=output_interval, tol_deg=tol_deg, hold_s=hold_s)
    else:
        programs = [(k, v) for k, v in (("voltage", voltage), ("duty", duty), ("current", current)) if v is not None]
        if len(programs) > 1:
            raise UsageProblem(f"give one drive program, not {' and '.join('--' + k for k, _ in programs)}")
        kind, program = programs[0] if programs else ("voltage", None)
        p = _load_params(params, set_ or [])
        spec = make_spec(p, strategy, profile, program, t_end, dt, method, output_interval, tol_deg, hold_s,
                         tol_m=tol_m, drive=kind)
    show = sys.stderr.isatty() if progress is None else progress
    result = run_spec(spec, progress=show)
    if out is not None:
        result.save(out)
    if summary is not None:
        result.write_summary(summary)
    if plot is not None:
        result.plot(plot, title=scenario)
    _print_summary(result)


def _print_summary(result) -> None:
    from rich.console import Console
    from rich.table import Table

    m = result.summary()
    u = result.spec.params.coordinate.unit
    console = Console()
    table = Table(title=f"{m['params']} / {m['strategy']}  ({m['steps']} steps, {1e3 * m['wall_s']:.1f} ms)")
    for col in ("segment", "start [s]", f"target [{u}]", "reached [s]", f"overshoot [{u}]"):
        table.add_column(col, justify="right")
    fmt = ".2f" if u == "deg" else ".5f"
    for s in m["segments"]:
        reached = "never" if s["reached_s"] is None else f"{s['reached_s']:.3f}"
        table.add_row(str(s["index"]), f"{s['start_s']:.3f}", format(s[f"target_{u}"], fmt), reached,
                      format(s[f"overshoot_{u}"], fmt))
    console.print(table)
    wires = result.spec.params.wire_names
    e, pt, ps = m["energy_J"], m["peak_temperature_C"], m["peak_stress_Pa"]
    console.print(
        "energy [J] " + " ".join(f"{w} {e[w]:.2f}" for w in wires)
        + " | peak T [°C] " + " ".join(f"{w} {pt[w]:.1f}" for w in wires)
        + " | peak stress [MPa] " + " ".join(f"{w} {ps[w] / 1e6:.2f}" for w in wires)
        + f" | interlock violations {m['interlock_violations']}"
    )


@app.command("params")
def params_cmd(
    name: Optional[str] = typer.Argument(None, help="a named set or FILE.toml to print as TOML"),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="override NAME=VALUE (repeatable)"),
    out: Optional[Path] = typer.Option(None, "--out", help="write the set to FILE.toml"),
):
    """List the named parameter sets, or print/save one as TOML."""
    if name is None:
        for n in names():
            p = resolve(n)
            typer.echo(f"{n} ({p.mechanism}): {p.source}")
        return
    p = _load_params(name, set_ or [])
    if out is not None:
        p.save(out)
    else:
        typer.echo(p.to_toml(), nl=False)


def _mount_optional() -> None:
    """Mount the sub-commands that live in their own modules."""
    try:
        from .cli_identify import app as identify_app

        app.add_typer(identify_app, name="identify", help="Fit model parameters to measured data.")
    except ImportError:
        pass
    try:
        from .cli_sweep import sweep

        app.command("sweep")(sweep)
    except ImportError:
        pass
    try:
        from .cli_reproduce import reproduce, scenarios_cmd

        app.command("reproduce")(reproduce)
        app.command("scenarios")(scenarios_cmd)
    except ImportError:
        pass


_mount_optional()


def main(argv: list[str] | None = None) -> int:
    """Entry point: usage errors print one line and exit with status 2."""
    try:
        rv = app(args=argv, standalone_mode=False, prog_name="smafinger")
        return rv if isinstance(rv, int) else 0
    except (UsageProblem, *USAGE_ERRORS) as exc:
        print(f"smafinger: error: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}", file=sys.stderr)
        return 2
    except SimulationError as exc:
        print(f"smafinger: simulation failed: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("smafinger: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        # typer's (vendored) click exceptions, matched by name: usage errors, exits, aborts
        kind = type(exc).__name__
        if kind == "Exit":
            return int(getattr(exc, "exit_code", 0))
        if kind == "Abort":
            print("smafinger: interrupted", file=sys.stderr)
            return 130
        if hasattr(exc, "format_message") and hasattr(exc, "exit_code"):
            msg = exc.format_message().replace("\n", " ")
            print(f"smafinger: error: {msg}", file=sys.stderr)
            return 2
        raise


def _console() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    _console()
