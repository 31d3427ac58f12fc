"""Bench recordings in and out: CSV, Parquet and MATLAB ``.mat`` files (issue 12's data layer).

Read one run with :func:`read_recording` (a :class:`Recording`: the input sent and the output
measured, each at its own sample times, in SI units), put it on a simulation grid with
:func:`input_on_grid`, :func:`output_on_grid` and :func:`input_program`, and write signals for
MATLAB with :func:`write_mat`. Layouts, mapping syntax and refusals: ``docs/recordings.md``.
"""

from .mapping import MappingError, SignalMap, Source, parse_map_options
from .matwrite import matlab_name, write_mat
from .reader import read_recording
from .recording import Recording, Series
from .resample import OutputSamples, input_on_grid, input_program, output_on_grid
from .signals import SIGNALS, RecordingError, SignalSpec

__all__ = [
    "read_recording", "Recording", "Series", "RecordingError", "MappingError", "SignalMap", "Source",
    "parse_map_options", "input_on_grid", "output_on_grid", "OutputSamples", "input_program",
    "write_mat", "matlab_name", "SIGNALS", "SignalSpec",
]
