"""Named, versioned scenarios: the simulations behind the paper's figures, and their claims.

Each scenario reproduces one curve of a figure of Gilardi, Haslam, Bundhoo & Park,
Robotica 28(5):675-687 (2010), or one of the two example profiles of the authors' public
2020 Simulink model. A name ends in a version (``-v1``): a scenario whose definition changes
gets a new version, so that a name always means the same definition: the parameter set (by its
name), its overrides, the strategy, the profile or drive program and the duration
(:meth:`.Scenario.definition_sha256`, recorded in ``tests/golden/scenario_definitions.json``).
Its results follow the model and the named sets' values: the golden record
(``tests/golden/paper_runs.json``) holds them, and every change to them is named in
``docs/changes/``.

>>> from smafinger import scenarios
>>> s = scenarios.get("fig8-h0-60-upper-v1")
>>> s.figure
'Fig. 8'
>>> spec = s.spec()                       # a validated RunSpec
>>> spec = s.spec(overrides=["M_SF_Nm=0.02"], dt_s=5e-4)

The scenarios and claims are declared figure by figure (:mod:`.sec31`, :mod:`.sec4`,
:mod:`.fig10`, :mod:`.fig11`, :mod:`.fig15`, :mod:`.authors`); this module is their registry. Adding a scenario or a
claim is one entry in the figure's module. The readings they share are in
:mod:`.scenario` and ``docs/reproduce.md``.
"""

from __future__ import annotations

from types import MappingProxyType

from . import authors, fig10, fig11, fig15, sec4, sec31
from .claim import Claim
from .overrides import Overrides
from .scenario import MOVE_S, OPEN_LOOP_ON_S, PAPER_FRICTION, Figure, Scenario

#: every output figure, in the paper's order
FIGURES: tuple[Figure, ...] = (sec31.FIGURES + fig10.FIGURES + fig11.FIGURES + sec4.FIGURES + fig15.FIGURES
                                + authors.FIGURES)
#: claims about every run rather than one figure
GENERAL_CLAIMS: tuple[Claim, ...] = (authors.INTERLOCK,)


def _registry() -> MappingProxyType:
    out: dict[str, Scenario] = {}
    for f in FIGURES:
        for s in f.scenarios:
            if s.name in out:
                raise ValueError(f"duplicate scenario {s.name!r}")
            out[s.name] = s
    return MappingProxyType(out)


_REGISTRY = _registry()


def names() -> list[str]:
    """Every scenario name, in registry order (figure by figure)."""
    return list(_REGISTRY)


def get(name: str) -> Scenario:
    """The scenario called ``name``; ``ValueError`` naming the known ones otherwise."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise ValueError(f"unknown scenario {name!r} (known: {', '.join(_REGISTRY)})") from None


def all_scenarios() -> list[Scenario]:
    return list(_REGISTRY.values())


def groups() -> dict[str, list[Scenario]]:
    """Scenarios by output figure, in registry order."""
    return {f.key: list(f.scenarios) for f in FIGURES}


def figure(key: str) -> Figure:
    """The output figure ``key`` (a scenario's ``group``)."""
    for f in FIGURES:
        if f.key == key:
            return f
    raise ValueError(f"unknown figure {key!r} (known: {', '.join(f.key for f in FIGURES)})")


def claims() -> list[Claim]:
    """Every claim: figure by figure, then the general ones."""
    return [c for f in FIGURES for c in f.claims] + list(GENERAL_CLAIMS)


__all__ = ["Scenario", "Figure", "Overrides", "Claim", "FIGURES", "names", "get", "all_scenarios", "groups",
           "figure", "claims", "PAPER_FRICTION", "OPEN_LOOP_ON_S", "MOVE_S"]
