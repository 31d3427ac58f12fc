"""``smafinger params``: list the named parameter sets, print or save one as TOML."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from .common import load_params
from .errors import NOTHING_WRITTEN, command


@command(interrupted=NOTHING_WRITTEN)
def params(
    name: Optional[str] = typer.Argument(None, metavar="[NAME|FILE.toml]", help="a named set or a parameter file to print as TOML"),
    set_: Optional[List[str]] = typer.Option(None, "--set", metavar="NAME=VALUE", help="override a parameter (repeatable)"),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FILE.toml", help="write the set to FILE.toml"),
):
    """List the named parameter sets, or print/save one as TOML."""
    from ..export import check_suffix
    from ..files import Outputs, check_output
    from ..parameters import names, resolve
    from .errors import UsageError

    if name is None and (out is not None or set_):
        given = "--out" if out is not None else "--set"
        raise UsageError(f"{given} needs a set: smafinger params NAME|FILE.toml {given} ...")
    if name is None:
        for n in names():
            p = resolve(n)
            typer.echo(f"{n} ({p.mechanism}): {p.source}")
        return
    if out is not None:
        check_output(out, "--out")  # a bad path is refused before anything is loaded
        check_suffix(out, (".toml",), "--out")
    text = load_params(name, set_, "parameter set").to_toml()
    if out is None:
        typer.echo(text, nl=False)
    else:
        Outputs().add(out, lambda tmp: Path(tmp).write_text(text), "--out").commit()
