"""CLI commands ``smafinger reproduce`` and ``smafinger scenarios`` (mounted by :mod:`.cli`)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import List, Optional

import typer


def reproduce(
    out: Path = typer.Option(Path("smafinger-reproduce"), "--out", help="output directory (created if needed)"),
    only: Optional[List[str]] = typer.Option(
        None, "--only", help="run only this scenario; a name or a glob pattern such as 'fig8-*' (repeatable)"),
    workers: Optional[int] = typer.Option(None, "--workers", help="worker processes (default: every available core)"),
    investigate: Optional[bool] = typer.Option(
        None, "--investigate/--no-investigate",
        help="run the full-cycle readings of Fig. 15 (default: when both Fig. 15 scenarios run)"),
    progress: Optional[bool] = typer.Option(None, "--progress/--no-progress", help="progress bar (default: on a terminal)"),
):
    """Run the paper's scenarios; write its figures, a CSV per run, summary.json and report.md."""
    from rich.console import Console
    from rich.table import Table

    from .paper.claim import Verdict
    from .paper.runner import reproduce as run

    if workers is not None and workers < 1:
        raise ValueError(f"--workers {workers}: must be >= 1")
    show = sys.stderr.isatty() if progress is None else progress
    res = run(out, only=only, workers=workers, progress=show, investigate=investigate)
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
    if res.failed:
        console.print(f"[red]{len(res.failed)} run(s) failed:[/red] {', '.join(res.failed)}")
        raise typer.Exit(1)


def scenarios_cmd(
    verbose: bool = typer.Option(False, "--verbose", "-v", help="also print each scenario's description and settings"),
):
    """List the named scenarios (name and the figure it reproduces)."""
    from .paper import scenarios

    for s in scenarios.all_scenarios():
        typer.echo(f"{s.name:34s} {s.figure}")
        if verbose:
            typer.echo(f"    {s.description}")
            how = f"profile {s.profile!r}" if s.profile else f"voltage {s.voltage!r}"
            typer.echo(f"    params {s.params}, strategy {s.strategy}, {how}, {s.t_end_s:g} s"
                       + (f", overrides {' '.join(s.overrides.texts())}" if s.overrides.texts() else ""))
