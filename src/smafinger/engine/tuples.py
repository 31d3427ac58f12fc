"""Per-wire tuples in compiled code: numba has no map over a tuple, so these helpers do it.

A run's wires are a homogeneous tuple (one record type), so numba indexes it at run time and
knows its length at compile time. ``out = filled(wires, ZERO)`` makes a tuple of the right
length; ``out = set_item(out, i, f(wires[i]))`` replaces an item (a new tuple, by value).

``set_item`` is generated for the tuple's length as a chain of ``if i == k`` rebuilding the
tuple: numba's own ``tuple_setitem`` stores through a stack slot at a run-time index, which LLVM
cannot keep in registers, and that slowed the engine two-fold.

Each helper's Python body does the same in plain Python, for the interpreted engine
(:mod:`.interpreted`, numba's JIT disabled).
"""

from numba import types
from numba.extending import overload


def set_item(tup, i, value):
    """A copy of the homogeneous tuple ``tup`` with item ``i`` replaced."""
    return tup[:i] + (value,) + tup[i + 1:]


@overload(set_item)
def _set_item(tup, i, value):
    if not isinstance(tup, types.BaseTuple):
        return None
    n = len(tup)
    lines = ["def impl(tup, i, value):"]
    for k in range(n):
        items = ", ".join("value" if j == k else f"tup[{j}]" for j in range(n))
        lines.append(f"    {'if' if k == 0 else 'elif'} i == {k}:\n        return ({items},)")
    lines.append("    return tup")
    ns: dict = {}
    exec("\n".join(lines) + "\n", ns)
    return ns["impl"]


def filled(template, value):
    """A tuple as long as ``template`` with every item ``value``."""
    return (value,) * len(template)


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

    numba has no ``_replace``; in compiled code ``value`` must have the field's type.
    """
    return record._replace(**{name: value})


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
