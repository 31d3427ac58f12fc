"""``smafinger reproduce`` (the paper's scenarios, figures and claims) and ``smafinger scenarios``."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from .common import progress_display, progress_option
from .errors import UsageError, WorkFailed, command, reading_input


@command(interrupted="no output was written; --out is as it was")
def reproduce(
    out: Path = typer.Option(Path("smafinger-reproduce"), "--out", metavar="DIR", help="output folder (created if needed)"),
    only: Optional[List[str]] = typer.Option(
        None, "--only", metavar="NAME|PATTERN",
        help="run only this scenario; a name or a glob pattern such as 'fig8-*' (repeatable)"),
    workers: Optional[int] = typer.Option(None, "--workers", metavar="N", help="worker processes (default: every available core)"),
    investigate: Optional[bool] = typer.Option(
        None, "--investigate/--no-investigate",
        help="run the full-cycle readings and studies of Fig. 15 (default: when every scenario they read runs)"),
    progress: Optional[bool] = progress_option(),
):
    """Run the paper's scenarios; write its figures, a CSV per run, summary.json and report.md."""
    from ..engine.forking import start_forkserver  # the standard library only

    start_forkserver(workers)  # its imports and kernel loading overlap this process's own
    from ..paper.runner import check_investigate, check_out_dir, select
    from ..paper.runner import reproduce as run

    with reading_input():
        # an unknown name, or --investigate without its scenarios, is refused before anything is made
        check_investigate([s.name for s in select(only)], investigate)
    if workers is not None and workers < 1:
        raise UsageError(f"--workers {workers}: must be >= 1")
    check_out_dir(out)  # before any run: a file, a missing parent, a folder holding other files
    res = None  # set once the outputs are in place: a Ctrl-C from then on (the display's teardown,
    # the printing) is not "no output was written" (found by review)
    try:
        with progress_display(progress) as display:
            res = run(out, only=only, workers=workers, progress=display, investigate=investigate)
        _print(res)
    except KeyboardInterrupt:
        if res is not None:
            raise KeyboardInterrupt(f"interrupted (Ctrl-C) after the outputs were written to {out}") from None
        raise
    if res.failed:
        raise WorkFailed(f"{len(res.failed)} run(s) failed: {', '.join(res.failed)} (see summary.json)")


def _print(res) -> None:
    from rich.console import Console
    from rich.table import Table

    from ..paper.claim import Verdict

    console = Console()
    table = Table(title=f"Gilardi et al. (2010) reproduced: {len(res.runs)} runs in {res.wall_s:.1f} s")
    for col in ("Figure", "Claim", "Paper", "Holds"):
        table.add_column(col, overflow="fold")
    skipped, broken = 0, 0
    for o in res.claims:
        if o.verdict is Verdict.NOT_RUN:
            skipped += not o.runs_failed
            broken += bool(o.runs_failed)
            continue
        table.add_row(o.claim.figure, o.claim.statement, o.claim.paper, o.verdict.value)
    console.print(table)
    if broken:
        console.print(f"{broken} claim(s) not evaluated: a run they need failed")
    if skipped:
        console.print(f"{skipped} claim(s) not run: their scenarios were not selected")
    console.print(f"smafinger's values, notes and the full-cycle investigation: {res.out_dir / 'report.md'}")
    console.print(f"figures, runs/*.csv and summary.json in {res.out_dir}/")


@command()
def scenarios(
    verbose: bool = typer.Option(False, "--verbose", "-v", help="also print each scenario's description and settings"),
):
    """List the named scenarios (name and the figure it reproduces)."""
    from ..paper import scenarios as registry

    for s in registry.all_scenarios():
        typer.echo(f"{s.name:34s} {s.figure}")
        if verbose:
            typer.echo(f"    {s.description}")
            how = f"profile {s.profile!r}" if s.profile else f"voltage {s.voltage!r}"
            typer.echo(f"    params {s.params}, strategy {s.strategy}, {how}, {s.t_end_s:g} s"
                       + (f", overrides {' '.join(s.overrides.texts())}" if s.overrides.texts() else ""))
