"""``smafinger sweep SPEC.toml``: a parametric sweep on local cores or a Dask cluster.

Registered by :mod:`smafinger.cli` as ``app.command("sweep")(sweep)``; also runnable alone
as ``python -m smafinger.cli_sweep SPEC.toml ...``.
"""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import Optional

import typer


def _fail(msg: str, code: int = 2):
    first = str(msg).splitlines()[0] if str(msg) else "error"
    print(f"smafinger: error: {first}", file=sys.stderr)
    raise typer.Exit(code)


def sweep(
    spec: Path = typer.Argument(..., help="sweep spec (TOML): [base], [sweep], [vary]; see docs/sweeps.md",
                                show_default=False),
    out: Optional[Path] = typer.Option(None, "--out", "-o",
                                       help="results table FILE.parquet (default: SPEC_NAME.parquet here); "
                                            "finished runs go to FILE.parquet.parts/ until the end"),
    workers: Optional[int] = typer.Option(None, "--workers", "-w",
                                          help="local worker processes (default: every core; 1: no pool)"),
    scheduler: Optional[str] = typer.Option(None, "--scheduler",
                                            help="run on this Dask cluster, tcp://HOST:PORT "
                                                 "(needs pip install 'smafinger[distributed]')"),
    traces: bool = typer.Option(False, "--traces/--no-traces",
                                help="also write the runs' sampled signals to FILE.traces.parquet"),
):
    """Run many simulations over a grid, a list, or random/Latin-hypercube samples of parameters.

    Writes one row per run (run_id, varied values, metrics). Interrupted (Ctrl-C, kill) and run
    again with the same spec and --out, it skips the runs already finished.
    """
    from rich.console import Console

    from .analysis.sweep import SweepInterrupted, SweepSpecError, load_spec, run_sweep
    from .engine.batch import BatchError, DistributedMissing

    if workers is not None and workers < 1:
        _fail(f"--workers {workers}: must be >= 1")
    if scheduler is not None:
        if workers is not None:
            _fail("--workers applies to local runs only; with --scheduler the cluster's workers are used")
        if "://" not in scheduler and ":" not in scheduler:
            _fail(f"--scheduler {scheduler!r}: expected an address like tcp://HOST:PORT")
        try:
            import distributed  # noqa: F401
        except ImportError:
            _fail("--scheduler needs dask.distributed, which is not installed: pip install 'smafinger[distributed]'")
    try:
        sweep_spec = load_spec(spec)
        sweep_spec.runs()  # validate every point before anything runs or is written
    except SweepSpecError as exc:
        _fail(str(exc))
    console = Console(stderr=True)
    previous = _term_as_interrupt()
    try:
        report = run_sweep(sweep_spec, out, workers=workers, scheduler=scheduler, traces=traces,
                           progress=console.is_terminal, console=console)
    except SweepInterrupted as exc:
        print(f"smafinger: {exc}", file=sys.stderr)
        raise typer.Exit(130)
    except KeyboardInterrupt:
        print("smafinger: interrupted", file=sys.stderr)
        raise typer.Exit(130)
    except SweepSpecError as exc:
        _fail(str(exc))
    except DistributedMissing as exc:
        _fail(str(exc))
    except BatchError as exc:
        _fail(str(exc), code=1)
    finally:
        _restore_term(previous)
    extra = f" and {report.traces_out}" if report.traces_out else ""
    typer.echo(f"wrote {report.out}{extra}: {report.total} runs ({report.resumed} already done, "
               f"{report.failed} failed) in {report.wall_s:.1f} s on {report.backend}")


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


def main() -> None:  # pragma: no cover - thin wrapper
    typer.run(sweep)


if __name__ == "__main__":  # pragma: no cover
    main()
