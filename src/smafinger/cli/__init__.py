"""Command-line interface: ``smafinger simulate | params | scenarios | reproduce | identify | sweep |
bench-controllers | tune``.

Each command is a thin function in its own module here (parse the options, call the API,
print); they are mounted below by explicit imports, so a broken import fails loudly. Errors
and exit statuses follow one policy (:mod:`.errors`). ``main(argv)`` returns the exit status;
the console script ``smafinger`` and ``python -m smafinger.cli`` call it.
"""

from __future__ import annotations

import gc
import os
import sys

import typer

from .bench import bench_controllers, tune
from .common import help_when_bare
from .errors import NOTHING_WRITTEN, command, run_app
from .identify import app as identify_app
from .params import params
from .reproduce import reproduce, scenarios
from .simulate import simulate
from .sweep import sweep

app = typer.Typer(
    add_completion=False,
    invoke_without_command=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="Simulate, control and identify SMA wire actuators: the tendon-driven finger joint of Gilardi et al. 2010 and a bias-spring rig.",
)
app.callback()(help_when_bare)
app.command("simulate")(simulate)
app.command("params")(params)
app.command("scenarios")(scenarios)
app.command("reproduce")(reproduce)
app.add_typer(identify_app, name="identify", help="Fit model parameters to measured data.")
app.command("sweep")(sweep)
app.command("bench-controllers")(command(interrupted=NOTHING_WRITTEN)(bench_controllers))
app.command("tune")(command(interrupted=NOTHING_WRITTEN)(tune))


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default: ``sys.argv[1:]``); returns the exit status.

    The commands write their figures to files: matplotlib gets the Agg backend unless
    ``MPLBACKEND`` says otherwise (the library itself leaves the caller's backend alone)."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    return run_app(app, argv)


def _console() -> None:
    """The console script: run the command, then end the process.

    Before it ends, every object still alive is moved out of the garbage collector's sight
    (:func:`gc.freeze`): Python's teardown would otherwise pass over them all in its final
    collections, about 100,000 objects once numba is loaded, 0.3-0.4 s of a cached
    ``simulate``'s 1.5-2 s here (docs/speed.md). The teardown itself still runs: other threads
    are joined, exit handlers run, modules are cleared and open files flushed; only objects kept
    alive by a reference cycle alone are left to the end of the process uncollected.
    """
    code = main()
    gc.freeze()
    sys.exit(code)


__all__ = ["app", "main"]
