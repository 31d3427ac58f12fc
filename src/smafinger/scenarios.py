"""The named scenarios: a re-export of :mod:`smafinger.paper.scenarios` (where they live)."""

from .paper.scenarios import *  # noqa: F401,F403
from .paper.scenarios import __all__, __doc__  # noqa: F401
