"""What counts as a number at the API's edge: one rule for every check of an argument or field.

Python's and numpy's ints and floats are numbers (numpy registers its scalars with
:mod:`numbers`); a bool is not (``True`` is not 1 s), nor is text (``"6"``).
"""

from __future__ import annotations

import numbers


def is_real(value) -> bool:
    """A real number: an int or float of Python or numpy, not a bool (numpy's bool is no
    :class:`numbers.Real` either)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_whole(value) -> bool:
    """An integer of Python or numpy, not a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)
