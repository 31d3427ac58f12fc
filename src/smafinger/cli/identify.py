"""``smafinger identify``: fit model parameters to measured data.

- ``smafinger identify kinetics FILE... [--validate FILE...]``: the wire's cosine kinetics
  (Eqs. 9-10) from strain-temperature curves under constant load.
- ``smafinger identify joint --heating FILE --cooling FILE``: h0, h2 and C_DF of the heating
  and cooling phases from the joint's angle-vs-time curves (the paper's Fig. 9).
- ``smafinger identify actuator`` (issue 12): a whole actuator fitted to bench runs (duty or
  voltage in, position or angle out; CSV or MATLAB files) and checked on held-out runs
  (:mod:`.identify_actuator`).

Bad input (data, options, parameter files) prints one line and exits with status 2; the
outputs (``--out``, ``--report``, ``--plot``) are written together, only when all succeeded.
"""

from __future__ import annotations

from pathlib import Path
from typing import List, Literal, Optional

import typer

from .common import help_when_bare, load_params, progress_display, progress_option, repeated_file
from .errors import NOTHING_WRITTEN, UsageError, command, reading_input
from .identify_actuator import actuator

app = typer.Typer(add_completion=False, invoke_without_command=True, pretty_exceptions_enable=False,
                  rich_markup_mode=None, help="Fit model parameters to measured data.")
app.callback()(help_when_bare)

OUT_HELP = "fitted parameter file FIT.toml (simulate --params accepts it)"
REPORT_HELP = "fit report FIT.json"
PLOT_HELP = "data vs model figure FIT.png (.pdf, .svg)"


def _targets(out: Path | None, report: Path | None, plot: Path | None) -> list[tuple[Path, str]]:
    """The requested outputs, checked before any work (bad name or folder: exit 2)."""
    from ..export import PLOT_SUFFIXES, check_suffix
    from ..files import check_outputs

    targets = []
    for path, what, allowed in ((out, "--out", (".toml",)), (report, "--report", (".json",)),
                                (plot, "--plot", PLOT_SUFFIXES)):
        if path is not None:
            check_suffix(path, allowed, what)
            targets.append((path, what))
    check_outputs(targets)
    return targets


def _base(params: str, overrides: list[str] | None):
    """(the base set, what the fitted file starts from: a registry name or the set itself)."""
    from ..parameters import REGISTRY

    p = load_params(params, overrides)
    return p, (params if (params in REGISTRY and not overrides) else p)


def _finish(ident, targets) -> None:
    """Write every output together, then print the fit and its warnings (in that order: a closed
    standard output, ``| head``, must not cost the fit's files)."""
    import sys

    from ..files import Outputs, json_text

    outputs = Outputs()
    for path, what in targets:
        if what == "--out":
            text = ident.toml
        elif what == "--report":
            text = json_text(ident.report)
        else:
            fig, fmt = ident.figure(), path.suffix.lstrip(".").lower()
            outputs.add(path, lambda tmp, fig=fig, fmt=fmt: fig.savefig(tmp, dpi=110, format=fmt), what)
            continue
        outputs.add(path, lambda tmp, text=text: Path(tmp).write_text(text), what)
    written = outputs.commit()
    for line in ident.lines:
        typer.echo(line)
    sys.stdout.flush()
    for w in ident.warnings:
        typer.echo(f"smafinger: warning: {w}", err=True)
    for path in written:
        typer.echo(f"wrote {path}")


@app.command()
@command(interrupted=NOTHING_WRITTEN)
def kinetics(
    files: List[Path] = typer.Argument(..., metavar="FILE", help="strain-temperature files to fit (T [degC], strain [-], stress [MPa])"),
    validate: Optional[List[Path]] = typer.Option(None, "--validate", metavar="FILE", help="files only predicted, not fitted (repeatable)"),
    params: str = typer.Option("paper2010", "--params", metavar="BASE", help="base set (named or FILE.toml): D_A, and the rest of FIT.toml"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override NAME=VALUE of the base set (repeatable)"),
    fit_moduli: bool = typer.Option(True, "--fit-dm/--fix-dm", help="fit D_M, or hold it at the base value (D_A is always held: only 1/D_M - 1/D_A is observable)"),
    stress: Literal["mean", "row"] = typer.Option("mean", "--stress", help="stress the model sees: each curve's mean, or each row's"),
    loo: bool = typer.Option(True, "--loo/--no-loo", help="leave-one-level-out check (needs >= 3 fitted files)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FIT.toml", help=OUT_HELP),
    report: Optional[Path] = typer.Option(None, "--report", metavar="FIT.json", help=REPORT_HELP),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="FIT.png", help=PLOT_HELP),
    progress: Optional[bool] = progress_option("progress bars"),
):
    """Fit the cosine kinetics (A_S0, A_F0, M_S0, M_F0, c_A, c_M, eps_R, D_M) to all FILES at once."""
    from ..analysis.identify import identify_kinetics

    targets = _targets(out, report, plot)
    if (twice := repeated_file([*files, *(validate or [])])) is not None:
        raise UsageError(twice)
    base_set, base_spec = _base(params, set_)
    with progress_display(progress) as display:
        ident = identify_kinetics(files, validate or [], base_set, base_spec, fit_moduli, stress, loo, display)
    ident.report = {"command": "identify kinetics", "base": params, "overrides": list(set_ or []), **ident.report}
    _finish(ident, targets)


@app.command()
@command(interrupted=NOTHING_WRITTEN)
def joint(
    heating: List[Path] = typer.Option(..., "--heating", metavar="FILE", help="angle-vs-time CSV of a heating experiment (repeatable)"),
    cooling: List[Path] = typer.Option(..., "--cooling", metavar="FILE", help="angle-vs-time CSV of a heat-then-cool experiment (repeatable)"),
    heat_s: Optional[List[float]] = typer.Option(None, "--heat-s", metavar="S", help="heating time [s] before switch-off, one per --cooling file (else its voltage column)"),
    heating_voltage: Optional[float] = typer.Option(None, "--heating-voltage", metavar="V", help="drive [V] of heating files without a voltage column (default: V_H of --params)"),
    cooling_voltage: Optional[float] = typer.Option(None, "--cooling-voltage", metavar="V", help="drive [V] before switch-off for --heat-s (default: V_H of --params)"),
    params: str = typer.Option("paper2010", "--params", metavar="BASE", help="starting/base set (named or FILE.toml)"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override NAME=VALUE of the base set (repeatable)"),
    fit_msf: bool = typer.Option(False, "--fit-msf", help="also fit the static friction moment M_SF (from the heating curves)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FIT.toml", help=OUT_HELP),
    report: Optional[Path] = typer.Option(None, "--report", metavar="FIT.json", help=REPORT_HELP),
    plot: Optional[Path] = typer.Option(None, "--plot", metavar="FIT.png", help=PLOT_HELP),
    progress: Optional[bool] = progress_option("progress bars"),
):
    """Fit h0, h2, C_DF of the heating and of the cooling phase to joint angle curves (Fig. 9)."""
    from ..analysis.identify import identify_joint, joint_experiments

    targets = _targets(out, report, plot)
    base_set, base_spec = _base(params, set_)
    with reading_input():
        h_exps, c_exps = joint_experiments(
            heating, cooling, list(heat_s or []), base_set.V_H_V if heating_voltage is None else heating_voltage,
            base_set.V_H_V if cooling_voltage is None else cooling_voltage)
    with progress_display(progress) as display:
        ident = identify_joint(h_exps, c_exps, base_set, base_spec, fit_msf, display)
    ident.report = {"command": "identify joint", "base": params, "overrides": list(set_ or []), **ident.report}
    _finish(ident, targets)


# identify actuator (issue 12): fit a bench actuator to recorded runs, predict held-out ones
app.command("actuator")(command(interrupted=NOTHING_WRITTEN)(actuator))
