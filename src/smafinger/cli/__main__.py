"""``python -m smafinger.cli``: the ``smafinger`` command."""

from . import _console

_console()
