"""One error policy for every command: what is printed, and the exit status.

============  ===========================================================================
exit status   meaning
============  ===========================================================================
0             done
1             the work failed: a numerical blow-up (with what to change), runs of
              ``reproduce`` that failed, a file that could not be written, an internal error
2             bad input: one line ``smafinger: error: ...`` naming the option or field
              and the value (data whose fit is no valid parameter set too); nothing is written
3             ``sweep``: runs failed (every run, or any with ``--strict``)
130           interrupted (Ctrl-C; SIGTERM for sweeps): one line saying what was kept
141           the standard output was closed by its reader (``smafinger params | head -1``):
              nothing more is printed, as a tool killed by SIGPIPE would end
============  ===========================================================================

Every command is wrapped by :func:`command`, so it behaves the same whether it runs under
:func:`smafinger.cli.main` or alone; :func:`run_app` adds the parsing errors (unknown
options, bad numbers, values not among the choices). Set ``SMAFINGER_DEBUG=1`` to see the
traceback of an internal error.
"""

from __future__ import annotations

import functools
import os
import sys
import traceback
from contextlib import contextmanager

import typer
from typer.exceptions import TyperException

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_RUNS_FAILED, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
EXIT_BROKEN_PIPE = 141  #: 128 + SIGPIPE: what a shell reports for a tool that signal ended
#: the interruption note of commands that write their outputs only at the end
NOTHING_WRITTEN = "no output was written"


class UsageError(ValueError):
    """Bad input found by a command (exit status 2)."""


class WorkFailed(RuntimeError):
    """The work could not be done with valid input (exit status 1), e.g. runs of reproduce that failed."""


def _input_errors() -> tuple[type[BaseException], ...]:
    """Exception types that are bad input wherever they are raised."""
    from ..analysis.data import DataError
    from ..analysis.identify import IdentificationError
    from ..analysis.sweep_spec import SweepSpecError
    from ..engine.pools import DistributedMissing, SchedulerError
    from ..files import OutputError
    from ..parameters import ParameterError
    from ..profiles import ProfileError
    from ..provenance import ProvenanceError
    from ..recordings import RecordingError

    return (UsageError, DataError, IdentificationError, SweepSpecError, SchedulerError, DistributedMissing, OutputError,
            ParameterError, ProfileError, ProvenanceError, RecordingError)


def first_line(exc: BaseException | str) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _stdout_gone() -> bool:
    """Whether the standard output is a pipe whose reader has closed it (POLLERR on its write
    end), so that a BrokenPipeError is ``| head`` having read enough, not another pipe breaking."""
    import select

    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(events & select.POLLERR for _, events in poller.poll(0))
    except (OSError, ValueError, AttributeError):  # no file descriptor (captured), or no poll
        return False


def classify(exc: BaseException, interrupted: str = "") -> tuple[int, str]:
    """(exit status, the one line to print) for an exception escaping a command.

    A Ctrl-C is classified before anything is imported: it can land while numba is half
    imported, and importing the engine then raised an AttributeError of its own (found by review:
    a traceback and exit status 1 in about 2 of 24 Ctrl-Cs half a second into a sweep)."""
    if isinstance(exc, KeyboardInterrupt):
        said = str(exc).strip()
        return EXIT_INTERRUPTED, f"smafinger: {said}" if said else (
            "smafinger: interrupted (Ctrl-C)" + (f"; {interrupted}" if interrupted else ""))
    from ..engine.pools import BatchError
    from ..engine.run import SimulationError

    if isinstance(exc, _input_errors()):
        return EXIT_USAGE, f"smafinger: error: {first_line(exc)}"
    if isinstance(exc, SimulationError):
        return EXIT_FAILED, f"smafinger: simulation failed: {first_line(exc)}"
    if isinstance(exc, (WorkFailed, BatchError)):
        return EXIT_FAILED, f"smafinger: failed: {first_line(exc)}"
    if isinstance(exc, MemoryError):
        return EXIT_FAILED, "smafinger: out of memory: the run or its outputs do not fit; record less often or less time"
    if isinstance(exc, BrokenPipeError) and exc.filename is None and _stdout_gone():  # its reader went away
        return EXIT_BROKEN_PIPE, ""
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if exc.filename else ""
        return EXIT_FAILED, f"smafinger: error: {where}{exc.strerror or first_line(exc)}"
    return EXIT_FAILED, (f"smafinger: internal error: {type(exc).__name__}: {first_line(exc)} "
                         "(please report it; SMAFINGER_DEBUG=1 shows where)")


def _report(line: str) -> None:
    """Print the one line (after the traceback of an internal error, with SMAFINGER_DEBUG=1);
    no line (a closed standard output): point stdout at the null device, so that the flush at
    the process's end does not fail on the closed pipe again."""
    if not line:
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):  # stdout is no file descriptor (captured)
            pass
        return
    if line.startswith("smafinger: internal error") and os.environ.get("SMAFINGER_DEBUG"):
        traceback.print_exc()
    print(line, file=sys.stderr)


def command(interrupted: str = ""):
    """Decorate a command: any exception becomes one line on stderr and its exit status
    (:func:`classify`); ``interrupted`` is said after Ctrl-C."""
    def wrap(fn):
        @functools.wraps(fn)
        def run(*args, **kwargs):
            try:
                return fn(*args, **kwargs)
            except (typer.Exit, typer.Abort, SystemExit, GeneratorExit):
                raise
            except BaseException as exc:
                code, line = classify(exc, interrupted)
                _report(line)
                raise typer.Exit(code) from None
        return run
    return wrap


@contextmanager
def reading_input(what: str = ""):
    """Inside: ``ValueError`` and ``TypeError`` (a bad value on its way in) are bad input."""
    try:
        yield
    except (ValueError, TypeError) as exc:
        if isinstance(exc, _input_errors()):
            raise
        raise UsageError(f"{what}{': ' if what else ''}{first_line(exc)}") from None


def run_app(app: typer.Typer, argv: list[str] | None) -> int:
    """Run a typer app the way the console script does; returns the exit status."""
    try:
        rv = app(args=argv, standalone_mode=False, prog_name="smafinger")
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        print("smafinger: interrupted (Ctrl-C)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except TyperException as exc:  # click's parsing errors: unknown option, bad number, not a choice
        print(f"smafinger: error: {' '.join(exc.format_message().split())}", file=sys.stderr)
        return getattr(exc, "exit_code", EXIT_USAGE) or EXIT_USAGE
    except BaseException as exc:  # outside any command (e.g. Ctrl-C while parsing)
        if isinstance(exc, (SystemExit, GeneratorExit)):
            raise
        code, line = classify(exc)
        _report(line)
        return code
    return rv if isinstance(rv, int) else EXIT_OK
