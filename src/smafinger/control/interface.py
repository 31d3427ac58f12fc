"""The controller interface the compiled loop calls at every control tick.

A controller is a record (a ``NamedTuple`` of its parameters, built at the API edge by
:mod:`.params`) with two compiled functions:

- ``initial(ctrl, model) -> cstate``: its own state at t = 0 (any record; ``()`` for none);
- ``tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started)
  -> (commands, integrating, cstate)``: from the schedule ``s`` (target, the strategy's enable
  mask) and what its sensors measure of the plant (:func:`.sensing.measure`), a
  :class:`~.strategies.Command` per wire (duty, drive level, phase) until the next tick;
  ``integrating`` (1.0 or 0.0) runs or freezes the error integral the plant state carries.

:func:`control_tick` and :func:`initial_control_state` dispatch on the record's type at compile
time, so each record type compiles into its own copy of the loop and costs nothing in the others
(and a full compile of the loop each: the built-in laws therefore share one record type,
:class:`~.chain.ControlChain`). :data:`KINDS` lists them. The paper's PWM-PID is the record
:class:`~smafinger.model.records.Controller`; its tick (:func:`~.controller.pid_tick`) is the
engine's historical :func:`~.controller.pid_commands`, so its runs are bit-identical to those
made before this interface.
"""

from typing import NamedTuple

from numba import types
from numba.extending import overload

from ..model.records import Controller
from .chain import ControlChain, chain_initial, chain_tick
from .controller import pid_initial, pid_tick


class Kind(NamedTuple):
    record: type
    tick: object  #: compiled tick function
    initial: object  #: compiled initial-state function


#: every controller record and its compiled functions (the paper's PID: see the module docstring)
KINDS: tuple[Kind, ...] = (
    Kind(Controller, pid_tick, pid_initial),
    Kind(ControlChain, chain_tick, chain_initial),
)


_KIND_BY_RECORD = {k.record: k for k in KINDS}


def _kind(ctrl) -> Kind | None:
    """The kind of a controller record's numba type (compiled dispatch)."""
    if not isinstance(ctrl, types.BaseNamedTuple):
        return None
    return _KIND_BY_RECORD.get(ctrl.instance_class)


def _kind_of(ctrl) -> Kind:
    """The kind of a controller record (interpreted dispatch: numba's JIT disabled)."""
    return _KIND_BY_RECORD[type(ctrl)]


def control_tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started):
    """(commands, integrating, cstate) at a control tick (see the module docstring)."""
    return _kind_of(ctrl).tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started)


def initial_control_state(ctrl, model):
    """The controller's own state at t = 0."""
    return _kind_of(ctrl).initial(ctrl, model)


@overload(control_tick)
def _control_tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started):
    k = _kind(ctrl)
    if k is None:
        return None
    tick = k.tick

    def impl(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started):
        return tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started)
    return impl


@overload(initial_control_state)
def _initial_control_state(ctrl, model):
    k = _kind(ctrl)
    if k is None:
        return None
    init = k.initial
    return lambda ctrl, model: init(ctrl, model)
