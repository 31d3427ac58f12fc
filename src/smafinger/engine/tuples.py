"""Per-wire tuples in compiled code: numba has no map over a tuple, so these two do it.

A run's wires are a homogeneous tuple (one record type), so numba indexes it at run time and
knows its length at compile time. ``out = filled(wires, f(wires[0]))`` makes a tuple of the
right length; ``out = set_item(out, i, f(wires[i]))`` replaces an item (a new tuple, by value).
"""

from numba import types
from numba.cpython.unsafe.tuple import tuple_setitem
from numba.extending import overload

#: a copy of a homogeneous tuple with item i replaced (numba's tuple_setitem)
set_item = tuple_setitem


def filled(template, value):
    """A tuple as long as ``template`` with every item ``value`` (compiled code only)."""
    raise NotImplementedError("filled() is compiled code: call it from a numba function")


@overload(filled)
def _filled(template, value):
    if isinstance(template, types.BaseTuple):
        # generated for the template's length, known at compile time
        ns: dict = {}
        exec("def impl(template, value):\n    return (" + "value, " * len(template) + ")\n", ns)
        return ns["impl"]
    return None


def with_field(record, name, value):
    """A copy of the NamedTuple ``record`` with field ``name`` (a literal string) set to ``value``.

    Compiled code only (numba has no ``_replace``); ``value`` must have the field's type.
    """
    raise NotImplementedError("with_field() is compiled code: call it from a numba function")


@overload(with_field, prefer_literal=True)
def _with_field(record, name, value):
    if not (isinstance(record, types.BaseNamedTuple) and isinstance(name, types.StringLiteral)):
        return None
    fields = list(record.fields)
    k = fields.index(name.literal_value)
    items = ", ".join("value" if i == k else f"record[{i}]" for i in range(len(fields)))
    ns: dict = {"cls": record.instance_class}
    exec(f"def impl(record, name, value):\n    return cls({items})\n", ns)
    return ns["impl"]
