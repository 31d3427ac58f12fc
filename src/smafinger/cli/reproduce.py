"""``smafinger reproduce`` (the paper's scenarios, figures and claims) and ``smafinger scenarios``."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from .common import progress_display, progress_option
from .errors import UsageError, WorkFailed, command, reading_input


@command()
def reproduce(
    out: Path = typer.Option(Path("smafinger-reproduce"), "--out", metavar="DIR", help="output folder (created if needed)"),
    only: Optional[List[str]] = typer.Option(
        None, "--only", metavar="NAME|PATTERN",
        help="run only this scenario; a name or a glob pattern such as 'fig8-*' (repeatable)"),
    workers: Optional[int] = typer.Option(None, "--workers", metavar="N", help="worker processes (default: every available core)"),
    investigate: Optional[bool] = typer.Option(
        None, "--investigate/--no-investigate",
        help="run the full-cycle readings of Fig. 15 (default: when both Fig. 15 scenarios run)"),
    progress: Optional[bool] = progress_option(),
):
    """Run the paper's scenarios; write its figures, a CSV per run, summary.json and report.md."""
    from ..engine.forking import start_forkserver  # the standard library only

    start_forkserver(workers)  # its imports and kernel loading overlap this process's own
    from ..paper.runner import reproduce as run
    from ..paper.runner import select

    with reading_input():
        select(only)  # an unknown name is refused before anything is made
    if workers is not None and workers < 1:
        raise UsageError(f"--workers {workers}: must be >= 1")
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: is a file; give a folder (created if needed)")
    if not out.exists() and not out.parent.is_dir():
        raise UsageError(f"--out {out}: folder {out.parent} does not exist")
    with progress_display(progress) as display:
        res = run(out, only=only, workers=workers, progress=display, investigate=investigate)
    _print(res)
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
    skipped = 0
    for o in res.claims:
        if o.verdict is Verdict.NOT_RUN:
            skipped += 1
            continue
        table.add_row(o.claim.figure, o.claim.statement, o.claim.paper, o.verdict.value)
    console.print(table)
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
