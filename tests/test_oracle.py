"""The compiled right-hand side against the plain-Python oracle (``tests/oracle``), written apart from it.

At random states and held inputs, for both mechanisms, both stress laws, both Joule readings,
both thermal models with and without latent heat, and a kinetics branch of each hysteresis rule
(the memory rule's with its hold, its target and parent, and the major-loop guard),
:func:`smafinger.engine.rhs.derivative` equals the oracle's derivative in every component (and
every algebraic output), to a stated relative tolerance of the magnitude of the terms each value
is computed from. Trajectories: ``tests/test_oracle_trajectories.py``.
"""

from __future__ import annotations

import math
import sys
from functools import partial

import oracle
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from oracle import Affine, Held, Kinetics, MemoryBranch, Phase, Vars, WireHeld, WireVars
from oracle.material import cooling_curve, heating_curve

from smafinger.engine.rhs import derivative, geometry
from smafinger.model import hysteresis as hy
from smafinger.model.build import build_model
from smafinger.model.records import Inputs, State, WireInput, WireState
from smafinger.parameters import get
from smafinger.parameters.options import Hysteresis, JouleHeating, SpringInit, StressLaw, ThermalModel

#: rate law: both sides evaluate the same closed-form expressions in a different order, so
#: they agree to round-off (measured over 6,000 draws: at most 5.0e-14 of the terms' magnitude)
RTOL_RATE = 1e-12
#: algebraic law: the compiled solver stops once its step is below 1e-9 (1 + |sigma|)
#: (model/wire.py, algebraic_stress); the oracle solves to round-off (measured: at most 3.6e-10)
RTOL_ALGEBRAIC = 1e-9
#: tendon tension up to about 45 N in the paper's wire (the spring-slack inverse, Eq. 8, far up
#: its cosh stiffening)
JOINT_SIGMA_MAX_PA = 4e8

RULE_CODES = {Hysteresis.MEMORY: hy.MEMORY, Hysteresis.AUTHORS2020: hy.AUTHORS2020, Hysteresis.DEADBAND: hy.DEADBAND}
RATES = {"q": "q", "v": "v", "error_integral": "error_integral"}
WIRE_RATES = {"T_C": "T", "sigma_Pa": "sigma", "electrical_J": "electrical", "heat_J": "heat", "T_case_C": "T_case"}
WIRE_OUTPUTS = {"xi": "xi", "sigma_Pa": "sigma", "force_N": "force", "spring_m": "spring", "arm_m": "arm"}


def engine_branch(branch, p, T: float) -> hy.BranchRecord:
    """The model's record of an oracle branch (docs/hysteresis.md: xi = x0 + slope (g - g0))."""
    code = RULE_CODES[p.options.hysteresis]
    if isinstance(branch, MemoryBranch):
        b, a = branch.branch, branch.parent
        return hy.BranchRecord(code, branch.direction, b.x0, b.g0, b.slope, branch.extreme, branch.g_extreme,
                               branch.target, math.nan, a.x0, a.g0, a.slope, T, 0.0, 0, 0)
    if branch.phase is Phase.HOLD:  # the legacy rules' record: heating x0 = 0, slope xi_M0; cooling x0 = xi_A0
        d, x0, slope = 0, branch.held, 0.0
    elif branch.phase is Phase.HEATING:
        d, x0, slope = 1, 0.0, branch.start
    else:
        d, x0, slope = -1, branch.start, 1.0 - branch.start
    return hy.BranchRecord(code, d, x0, 0.0, slope, 0.0, 0.0, math.inf, x0, x0, 0.0, slope, T,
                           p.minor_loop_reversal_C, 0, 0)


def engine_values(p, s: Vars, u: Held) -> dict[str, float]:
    """The compiled derivative and outputs at the oracle's state and inputs, by the oracle's names."""
    model = build_model(p)
    state = State(s.q, s.v, s.error_integral,
                  tuple(WireState(w.T, w.sigma, w.electrical, w.heat, w.T_case, 0.0) for w in s.wires))
    inputs = Inputs(u.stuck, u.viscous, u.q_target, u.integrating, u.current, tuple(
        WireInput(w.drive, w.heating, engine_branch(w.branch, p, s.wires[i].T), 0) for i, w in enumerate(u.wires)))
    rate, aux = derivative(state, inputs, model, geometry(model, s.q))
    out = {"rate." + o: getattr(rate, e) for e, o in RATES.items()}
    out["out.load"] = aux.load
    for name, wr, wa in zip(p.wire_names, rate.wires, aux.wires):
        out.update({f"rate.{name}.{o}": getattr(wr, e) for e, o in WIRE_RATES.items()})
        out.update({f"out.{name}.{o}": getattr(wa, e) for e, o in WIRE_OUTPUTS.items()})
    return out


def oracle_values(p, s: Vars, u: Held) -> tuple[dict[str, float], dict[str, float]]:
    """(values, scales) of the oracle's derivative, keyed as :func:`engine_values`."""
    d = oracle.derivative(oracle.build(p), s, u, scales=True)
    values = {"rate." + k: v for k, v in d.rates.items()} | {"out." + k: v for k, v in d.outputs.items()}
    scales = {"rate." + k: v for k, v in d.rate_scales.items()} | {"out." + k: v for k, v in d.output_scales.items()}
    return values, scales


#: a difference this small is round-off among subnormal results, whose precision is absolute
#: (a drive of 5e-162 V, a normal number, gives a Joule heating rate of 1e-322 K/s; the engine and
#: the oracle, in different orders of operations, were 8.4e-323 and 1.1e-322 apart from zero)
SUBNORMAL_ROUNDING = sys.float_info.min


def disagreements(p, s, u, rtol) -> list[str]:
    """The components where engine and oracle differ by more than ``rtol`` of the terms' scale."""
    eng = engine_values(p, s, u)
    ora, scale = oracle_values(p, s, u)
    assert eng.keys() == ora.keys()
    bad = []
    for k in eng:
        err = abs(eng[k] - ora[k])
        if not err <= rtol * max(scale[k], abs(ora[k])) + SUBNORMAL_ROUNDING:
            bad.append(f"{k}: engine {eng[k]!r}, oracle {ora[k]!r} (scale {scale[k]:.3g}, rel {err / scale[k]:.3g})"
                       if scale[k] else f"{k}: engine {eng[k]!r}, oracle {ora[k]!r}")
    return bad


# --------------------------------------------------------------------------------------------
# random states
# --------------------------------------------------------------------------------------------
JOINT_SETS = ("paper2010", "paper2010-table2", "authors2020")
#: no subnormal numbers: their round-off is not a few units of 1e-16 of their size
floats = partial(st.floats, allow_subnormal=False)


@st.composite
def parameter_sets(draw):
    mechanism = draw(st.sampled_from(("joint", "slider")))
    changes = dict(stress_law=draw(st.sampled_from(list(StressLaw))),
                   joule_heating=draw(st.sampled_from(list(JouleHeating))),
                   hysteresis=draw(st.sampled_from(list(Hysteresis))),
                   thermal_model=draw(st.sampled_from(list(ThermalModel))),
                   latent_heat_J_kg=draw(st.one_of(st.just(0.0), floats(1e3, 1e5))),
                   casing_heat_capacity_J_mK=draw(floats(0.1, 100.0)),
                   casing_loss_W_mK=draw(floats(0.0, 2.0)), xi_init=draw(floats(0.0, 1.0)))
    if mechanism == "joint":
        base = get(draw(st.sampled_from(JOINT_SETS)))
        changes["spring_init"] = draw(st.sampled_from(list(SpringInit)))
    else:
        base = get("linear-bias-spring")
    return base.replace(**changes)


def temperatures(p, sigma):
    """Anywhere from -20 to 250 degC, or around either transformation band shifted by sigma (Eqs. 9-10).

    Inside a band xi depends on T and sigma, which brings in the coupling terms of Eq. (7b)
    and the latent heat; uniform draws over the whole range would seldom land there.
    """
    def band(lo, hi, c):
        shift = sigma / c
        return floats(lo + shift - 0.2 * (hi - lo), hi + shift + 0.2 * (hi - lo))

    return st.one_of(floats(-20.0, 250.0), band(p.A_S0_C, p.A_F0_C, p.c_A_Pa_per_C),
                     band(p.M_F0_C, p.M_S0_C, p.c_M_Pa_per_C))


@st.composite
def memory_branches(draw, p, T: float, sigma: float):
    """A memory-rule branch through this state's neighbourhood, as the rule builds one.

    Its anchor, extreme and target lie in that order along its direction, anywhere around the
    state's own tau (so the state may be back from the extreme: a hold; on the branch; or past
    the target: on the parent); anchor and target are points of the major loop, the branch the
    chord between them (aimed at the end of the major curve when there is no target), the
    parent any branch through the target. Its xi may leave the loop there (the guard clamps it).
    """
    m = oracle.build(p).wires[0].transformation
    d = draw(st.sampled_from((1, -1, 0)))
    if d == 0:  # not yet moved: holds its xi
        x = draw(floats(0.0, 1.0))
        return MemoryBranch(0, Affine(x, 0.0, 0.0), math.inf, 0.0, math.inf, Affine(x, 0.0, 0.0))
    tau = T - sigma / (m.c_A if d > 0 else m.c_M)
    marks = sorted(draw(st.lists(floats(tau - 30.0, tau + 30.0), min_size=3, max_size=3)), reverse=d < 0)
    anchor, extreme, target = marks
    if draw(st.booleans()):
        target = d * math.inf

    def g(t):  # the branch's major curve at its own tau t (zero stress: g depends on tau alone)
        return (heating_curve if d > 0 else cooling_curve)(t, 0.0, m)[0]

    def loop_point(t, lo=0.0, hi=1.0):  # xi between the major curves at tau t (and within [lo, hi])
        gA, gM = min(heating_curve(t, 0.0, m)[0], hi), max(cooling_curve(t, 0.0, m)[0], lo)
        return gM + draw(floats(0.0, 1.0)) * (gA - gM)

    x0, g0 = loop_point(anchor), g(anchor)
    if not math.isfinite(target):  # aimed at the end of the major curve
        x_t, g_t = (0.0, 0.0) if d > 0 else (1.0, 1.0)
    else:  # xi moves one way along a branch (down heating, up cooling); a flat branch keeps it
        g_t = g(target)
        x_t = x0 if g_t == g0 else loop_point(target, *((0.0, x0) if d > 0 else (x0, 1.0)))
    slope = 0.0 if g0 == g_t else (x0 - x_t) / (g0 - g_t)
    parent = Affine(x_t, g_t, draw(floats(0.0, 2.0)))
    return MemoryBranch(d, Affine(x0, g0, slope), extreme, g(extreme), target, parent)


@st.composite
def legacy_branches(draw):
    return Kinetics(draw(st.sampled_from(list(Phase))), draw(st.one_of(floats(0.0, 1.0), floats(-0.5, 1.5))),
                    draw(floats(0.0, 1.0)))


@st.composite
def cases(draw):
    p = draw(parameter_sets())
    joint = p.mechanism == "joint"
    n = len(p.wire_names)
    q_range = (-math.radians(89.0), math.radians(89.0)) if joint else (p.stroke_min_m, p.stroke_max_m)
    q = draw(floats(*q_range))
    v = draw(st.one_of(st.just(0.0), floats(-5.0, 5.0) if joint else floats(-0.5, 0.5)))
    sigma_max = JOINT_SIGMA_MAX_PA if joint else 6e8
    wires, branches = [], []
    # a slack tendon (sigma <= 0) with latent heat: test_latent_heat_of_a_slack_tendon
    sigma_min = 1.0 if p.latent_heat_J_kg else -0.25 * sigma_max
    for _ in range(n):
        sigma = draw(floats(sigma_min, sigma_max))
        T = draw(temperatures(p, sigma))
        wires.append(WireVars(T, sigma, draw(floats(0.0, 1e3)), draw(floats(0.0, 1e3)),
                              draw(floats(T - 60.0, T + 20.0))))
        branches.append(draw(memory_branches(p, T, sigma) if p.options.hysteresis is Hysteresis.MEMORY
                             else legacy_branches()))
    s = Vars(q, v, draw(floats(-10.0, 10.0)), tuple(wires))
    current = draw(st.booleans())
    held = tuple(WireHeld(draw(floats(0.0, 3.0 if current else 15.0)), draw(st.booleans()), b) for b in branches)
    u = Held(draw(st.booleans()), draw(floats(0.0, 0.2) if joint else floats(0.0, 5.0)),
             draw(floats(*q_range)), draw(st.sampled_from((0.0, 1.0))), current, held)
    return p, s, u


@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cases())
def test_compiled_rhs_equals_oracle_at_random_states(case):
    p, s, u = case
    rtol = RTOL_ALGEBRAIC if p.stress_law is StressLaw.ALGEBRAIC else RTOL_RATE
    bad = disagreements(p, s, u, rtol)
    assert not bad, f"{p.name} ({p.options.to_dict()}, dH = {p.latent_heat_J_kg}):\n" + "\n".join(bad)


def test_spring_slack_inverse_at_high_tension():
    """Rate law at 120 MPa (13 N in the paper's wire): the spring elongation and dsigma/dt.

    Found by the oracle: the compiled inverse's Newton iteration stopped short of the root above
    about 10 N (fixed in model/constitutive.py, which now brackets the root when Newton stalls).
    """
    p = get("paper2010").replace(hysteresis="authors2020")
    s = Vars(math.radians(-30.0), 0.3, 0.0, (WireVars(95.0, 1.2e8), WireVars(40.0, 1.2e8)))
    u = Held(False, 0.03, 0.0, 1.0, False, (WireHeld(8.0, True, Kinetics(Phase.HEATING, 1.0, 1.0)),
                                            WireHeld(0.0, False, Kinetics(Phase.HOLD, 1.0, 1.0))))
    assert not disagreements(p, s, u, RTOL_RATE)


def test_latent_heat_of_a_slack_tendon():
    """A slack upper tendon (sigma = 0) that slackens further, heated inside its band, dH = 24 kJ/kg.

    Its stress stays 0 (a tendon only pulls), so dxi/dt = xi_T dT/dt and the latent heat takes
    only that. Was a strict xfail: the model solved dT/dt with the unfloored stress rate of Eq.
    (7b), 5.047 degC/s against 5.486 (8 % low); model/wire.py ``_strain_driven`` now solves it
    with the floored one.
    """
    p = get("paper2010").replace(hysteresis="authors2020", latent_heat_J_kg=24e3)
    s = Vars(math.radians(-30.0), 0.5, 0.0, (WireVars(95.0, 0.0), WireVars(30.0, 5e7)))
    u = Held(False, 0.03, 0.0, 1.0, False, (WireHeld(8.0, True, Kinetics(Phase.HEATING, 1.0, 1.0)),
                                            WireHeld(0.0, False, Kinetics(Phase.HOLD, 1.0, 1.0))))
    assert oracle.derivative(oracle.build(p), s, u).rates["upper.sigma"] == 0.0  # floored: slack
    assert not disagreements(p, s, u, RTOL_RATE)
