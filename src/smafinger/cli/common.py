"""What the commands share: option types that list their choices in ``--help``, the
parameter-set option, and which options the user gave."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import typer

from ..progress import Display
from .choices import ENGINES, METHOD_NAMES, PWM_NAMES, STRATEGY_NAMES
from .errors import UsageError, reading_input

#: ``--strategy`` values (``--help`` lists them)
Strategy = Literal[STRATEGY_NAMES]
#: ``--method`` values
Method = Literal[METHOD_NAMES]
Pwm = Literal[PWM_NAMES]
#: ``--engine`` values (engine.interpreted)
Engine = Literal[ENGINES]


def given(ctx: typer.Context, *names: str) -> list[str]:
    """The options among ``names`` (parameter names) that were given on the command line,
    as their flags (``--t-end``)."""
    flags = {p.name: (p.opts[0] if p.opts else p.name) for p in ctx.command.params}
    out = []
    for name in names:
        source = ctx.get_parameter_source(name)
        if source is not None and source.name not in ("DEFAULT", "DEFAULT_MAP"):
            out.append(flags.get(name, name))
    return out


def refuse(ctx: typer.Context, names: tuple[str, ...], because: str) -> None:
    """:class:`UsageError` if any option of ``names`` was given: ``because`` says why."""
    clash = given(ctx, *names)
    if clash:
        raise UsageError(f"{' and '.join(clash)}: not used {because}")


def repeated_file(files) -> str | None:
    """Why one of ``files`` is given twice (one file under two spellings, ``./a.csv``, its absolute
    path or a link, is one file), or None: a file fitted twice weighs double, and one fitted and
    validated is not held out."""
    seen: dict[Path, str] = {}
    for f in map(str, files):
        key = Path(f).resolve()
        if key in seen:
            return f"{f}: given twice (as {seen[key]!r} and {f!r}); give each file once, with one role"
        seen[key] = f
    return None


def load_params(text: str, overrides: list[str] | None, what: str = "--params"):
    """The parameter set named by an option (a registry name or a .toml file) with ``--set``
    overrides; bad input raises :class:`UsageError` naming the option."""
    from ..parameters import resolve

    if not text.strip():
        raise UsageError(f"{what} {text!r}: give a named set (see 'smafinger params') or a .toml file")
    if Path(text).is_dir():
        raise UsageError(f"{what} {text}: is a folder, not a parameter file")
    with reading_input():
        return resolve(text).with_overrides(overrides or [])


def progress_display(flag: bool | None) -> Display:
    """The progress display of a ``--progress/--no-progress`` flag: a bar on a terminal, plain
    lines in a log when asked for, nothing otherwise."""
    return Display.auto(flag)


def progress_option(what: str = "progress bar"):
    return typer.Option(None, "--progress/--no-progress",
                        help=f"{what} on stderr (default: on a terminal; --progress in a log: a line every 10 s)")


def help_when_bare(ctx: typer.Context) -> None:
    """A command group's callback: given no sub-command, print the group's help (exit 0)."""
    if ctx.invoked_subcommand is None:
        typer.echo(ctx.get_help())
