"""What counts as a number at the API's edge: one rule for every check of an argument or field.

Python's and numpy's ints and floats are numbers (numpy registers its scalars with
:mod:`numbers`); a bool is not (``True`` is not 1 s), nor is text (``"6"``). Where a list of
values belongs, one value is a list of one (:func:`one_or_many`).
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Iterable


def is_real(value) -> bool:
    """A real number: an int or float of Python or numpy, not a bool (numpy's bool is no
    :class:`numbers.Real` either)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_whole(value) -> bool:
    """An integer of Python or numpy, not a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def one_or_many(values) -> list:
    """``values`` as a list; one value (text, a path, or anything not iterable) as a list of it
    (a string given where a list belongs was split into its letters: ``with_overrides("V_H_V=6")``
    read the override 'V'; found by an API fuzz)."""
    if isinstance(values, (str, bytes, os.PathLike)) or not isinstance(values, Iterable):
        return [values]
    return list(values)
