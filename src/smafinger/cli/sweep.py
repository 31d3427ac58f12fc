"""``smafinger sweep SPEC.toml``: a parametric sweep on local cores or a Dask cluster.

Exit status: 0 when the table is written and at least one run succeeded (failed runs are
rows with ``status = error``, counted on stderr); 3 when every run failed, or with
``--strict`` when any did; 2 for bad input (one line naming the field or the address,
nothing written); 1 when the sweep could not complete (a worker pool broke); 130 when
interrupted (finished runs are saved: run the same command again to resume).
"""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import Optional

import typer

from .errors import EXIT_RUNS_FAILED, UsageError, command


@command()
def sweep(
    spec: Path = typer.Argument(..., metavar="SPEC.toml", help="sweep spec (TOML): [base], [sweep], [vary]; see docs/sweeps.md",
                                show_default=False),
    out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE.parquet",
                                       help="results table (default: SPEC_NAME.parquet here); "
                                            "finished runs go to FILE.parquet.parts/ until the end"),
    mat: Optional[Path] = typer.Option(None, "--mat", metavar="FILE.mat",
                                       help="also write the table for MATLAB: a struct 'sweep' (struct2table) "
                                            "and its provenance"),
    workers: Optional[int] = typer.Option(None, "--workers", "-w", metavar="N",
                                          help="local worker processes (default: every core; 1: no pool)"),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", metavar="tcp://HOST:PORT",
                                            help="run on this Dask cluster: one you trust, its workers run pickled "
                                                 "code (needs pip install 'smafinger[distributed]')"),
    connect_timeout: float = typer.Option(10.0, "--connect-timeout", metavar="SECONDS",
                                          help="time allowed to reach the Dask scheduler"),
    traces: bool = typer.Option(False, "--traces/--no-traces",
                                help="also write the runs' sampled signals to FILE.traces.parquet"),
    max_runs: int = typer.Option(1_000_000, "--max-runs", metavar="N",
                                 help="refuse sweeps with more runs than this (their size is shown first)"),
    strict: bool = typer.Option(False, "--strict",
                                help=f"exit with status {EXIT_RUNS_FAILED} if any run failed (default: only if all did)"),
    progress_interval: float = typer.Option(10.0, "--progress-interval", metavar="SECONDS",
                                            help="when stderr is not a terminal: a progress line this often"),
):
    """Run many simulations over a grid, a list, or random/Latin-hypercube samples of parameters.

    Writes one row per run (run_id, varied values, metrics). Interrupted (Ctrl-C, kill) and run
    again with the same spec and --out, it skips the runs already finished. Exit status: 0 if
    at least one run succeeded, 3 if all failed (or any, with --strict), 2 for bad input.
    """
    from rich.console import Console

    from ..engine.forking import start_forkserver  # the standard library only

    _check_options(workers, max_runs, progress_interval, scheduler, mat)
    if scheduler is None:
        start_forkserver(workers)  # its imports and kernel loading overlap this process's own
    from ..analysis.sweep import load_spec, run_sweep
    from ..engine.batch import check_scheduler

    sweep_spec = load_spec(spec, max_runs=max_runs)
    if scheduler is not None:
        scheduler = check_scheduler(scheduler, connect_timeout)  # fail fast, before any work
    console = Console(stderr=True)
    previous = _term_as_interrupt()
    try:
        report = run_sweep(sweep_spec, out, workers=workers, scheduler=scheduler, traces=traces,
                           progress=console.is_terminal, console=console, max_runs=max_runs,
                           connect_timeout_s=connect_timeout, progress_interval_s=progress_interval)
    finally:
        _restore_term(previous)
    if mat is not None:
        from ..analysis.sweep_provenance import write_table_mat

        write_table_mat(report.out, mat)
    extra = "".join(f" and {p}" for p in (report.traces_out, mat) if p)
    typer.echo(f"wrote {report.out}{extra}: {report.total} runs ({report.resumed} already done, "
               f"{report.failed_total} failed) in {report.wall_s:.1f} s on {report.backend}")
    if report.flagged_total:
        print(f"smafinger: {report.flagged_total} of {report.total} runs have warnings (physically absurd results, "
              "a target never pursued, or with check_step a step the run has not converged at; see their warnings "
              "column)", file=sys.stderr)
    if report.unchecked_total:
        print(f"smafinger: {report.unchecked_total} of {report.total} runs were not step-checked: their rows were "
              f"made before check_step was on, and were kept; delete {report.out} to check them",
              file=sys.stderr)
    if report.failed_total:
        every = report.failed_total == report.total
        print(f"smafinger: {'every run' if every else f'{report.failed_total} of {report.total} runs'} failed "
              "(rows with status = error; see their error column)", file=sys.stderr)
        if every or strict:
            raise typer.Exit(EXIT_RUNS_FAILED)


def _check_options(workers, max_runs, progress_interval, scheduler, mat) -> None:
    from ..files import check_output

    if workers is not None and workers < 1:
        raise UsageError(f"--workers {workers}: must be >= 1")
    if max_runs < 1:
        raise UsageError(f"--max-runs {max_runs}: must be >= 1")
    if not progress_interval > 0:
        raise UsageError(f"--progress-interval {progress_interval}: must be > 0")
    if mat is not None:
        if mat.suffix.lower() != ".mat":
            raise UsageError(f"--mat {mat}: the file name must end in .mat")
        check_output(mat, "--mat")
    if scheduler is not None:
        if workers is not None:
            raise UsageError("--workers applies to local runs only; with --scheduler the cluster's workers are used")
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise UsageError("--scheduler needs dask.distributed, which is not installed: "
                             "pip install 'smafinger[distributed]'") from None


def _term_as_interrupt():
    """SIGTERM stops the sweep like Ctrl-C (finished runs are saved)."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def handler(signum, frame):
        raise KeyboardInterrupt

    return signal.signal(signal.SIGTERM, handler)


def _restore_term(previous) -> None:
    if previous is not None:
        signal.signal(signal.SIGTERM, previous)
