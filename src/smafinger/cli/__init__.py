"""Command-line interface: ``smafinger simulate | params | scenarios | reproduce | identify | sweep``.

Each command is a thin function in its own module here (parse the options, call the API,
print); they are mounted below by explicit imports, so a broken import fails loudly. Errors
and exit statuses follow one policy (:mod:`.errors`). ``main(argv)`` returns the exit status;
the console script ``smafinger`` and ``python -m smafinger.cli`` call it.
"""

from __future__ import annotations

import sys

import typer

from .common import help_when_bare
from .errors import run_app
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
    help="Simulate, control and identify SMA tendon-driven finger joints (Gilardi et al. 2010).",
)
app.callback()(help_when_bare)
app.command("simulate")(simulate)
app.command("params")(params)
app.command("scenarios")(scenarios)
app.command("reproduce")(reproduce)
app.add_typer(identify_app, name="identify", help="Fit model parameters to measured data.")
app.command("sweep")(sweep)


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default: ``sys.argv[1:]``); returns the exit status."""
    return run_app(app, argv)


def _console() -> None:
    sys.exit(main())


__all__ = ["app", "main"]
