"""``smafinger reproduce``: a re-export of :mod:`smafinger.paper.runner` (where it lives).

The metrics are in :mod:`smafinger.metrics`, the claims with their scenarios in
:mod:`smafinger.paper.scenarios`, the Fig. 15 readings in :mod:`smafinger.paper.investigation`.
"""

from .paper.derived import Run
from .paper.investigation import READINGS
from .paper.investigation import tasks as investigation_tasks
from .paper.runner import ReproduceOutput, reproduce, run_tasks, select

__all__ = ["reproduce", "select", "run_tasks", "investigation_tasks", "READINGS", "Run", "ReproduceOutput"]
