"""Hypothesis strategies for the fuzz suite: command lines, parameter files, profiles, drive
programs, sweep specs and data files, each a mix of sane values and nasty ones.

Runs are kept short (at most a few simulated seconds, or a named scenario) so that a case
that is accepted finishes in well under a second; the nasty values are the ones a run must
refuse (beyond the clock, beyond memory, not numbers, not whole nanoseconds ...).
"""

from __future__ import annotations

import math
import random

from hypothesis import strategies as st

from fuzz_runner import Case
from smafinger.engine.integrators import INTEGRATORS
from smafinger.engine.pwm import PWM_MODELS
from smafinger.parameters import MECHANISMS, get, names
from smafinger.parameters.options import OPTION_NAMES

PARAM_SETS = names()
FIELDS = sorted({f for cls in MECHANISMS.values() for f in cls.field_names()})
SCENARIOS = ["fig12-extension-v1", "fig8-h0-60-upper-v1", "fig13-flexion-case2-v1", "authors2020-profile1-v1"]
JUNK = ["", " ", "abc", "nan", "inf", "-inf", "1e400", "--", "0x10", "1,5", "∞", "\x00", "None", "true", "[]"]

#: numbers as they may be typed: sane ones and nasty ones
NASTY_FLOATS = [0.0, -0.0, -1.0, 1e-300, 1e-12, 1.5e-10, 2e-10, 1e10, 9.3e9, 1e308, -1e308, math.inf, -math.inf,
                math.nan]


def _uniform() -> st.SearchStrategy:
    """A uniform number in [0, 1): hypothesis' own floats and randoms lean to 0 (to find edge
    cases); a seeded generator's first number does not, whatever the seed."""
    return st.integers(0, 2**32 - 1).map(lambda seed: random.Random(seed).random())


def chance(draw, p: float) -> bool:
    """True with probability ``p``."""
    return draw(_uniform()) < p


def mostly(sane: st.SearchStrategy, nasty: st.SearchStrategy, p_nasty: float = 0.05) -> st.SearchStrategy:
    """``sane`` values, and ``nasty`` ones with probability ``p_nasty``."""
    return _uniform().flatmap(lambda u: nasty if u < p_nasty else sane)


def number_text(sane: st.SearchStrategy) -> st.SearchStrategy:
    return mostly(sane.map(repr), st.one_of(st.sampled_from(NASTY_FLOATS).map(repr), st.sampled_from(JUNK)))


T_END = number_text(st.floats(0.001, 3.0))
DT = number_text(st.sampled_from([1e-3, 5e-4, 2e-3, 1e-4, 0.01, 0.05]))
OUTPUT_INTERVAL = number_text(st.sampled_from([1e-3, 0.01, 0.1, 0.5, 2e-3, 3e-4]))
TOLERANCE = number_text(st.floats(0.0, 5.0))


@st.composite
def profile_text(draw) -> str:
    n = draw(mostly(st.integers(1, 5), st.just(0)))
    t, items = 0.0, []
    for i in range(n):
        if i == 0:
            start = draw(mostly(st.sampled_from(["0", "0.0"]), st.sampled_from(["1", "reach", "-1", "x"])))
        else:
            t += draw(st.floats(0.01, 2.0))
            start = draw(mostly(st.sampled_from([repr(t), "reach", "r"]), st.sampled_from(["1e10", "nan", "", "-3", "0"])))
        target = draw(mostly(st.one_of(st.floats(-60.0, -20.0).map(repr), st.sampled_from(["-25", "-55", "0.01"])),
                             st.sampled_from(["1e9", "x", "nan", "", "90", "-200"])))
        parts = [start, target]
        if draw(st.booleans()):
            parts.append(draw(mostly(st.sampled_from(["auto", "none", "both", "upper", "lower"]),
                                     st.sampled_from(["wire", "all", "??", ""]))))
        items.append(":".join(parts))
    sep = draw(mostly(st.just(","), st.sampled_from([", ", ";", " "])))
    return sep.join(items)


@st.composite
def program_text(draw) -> str:
    n = draw(mostly(st.integers(1, 4), st.just(0)))
    width = draw(mostly(st.just(2), st.sampled_from([1, 3])))
    t, items = 0.0, []
    for i in range(n):
        if i:
            t += draw(mostly(st.sampled_from([0.5, 1.0]) | st.floats(0.001, 2.0),
                             st.sampled_from([0.0, 1e10, -1.0, 1e-10])))
        values = [draw(mostly(st.sampled_from(["0", "8", "0", "5", "0.3"]) | st.floats(0.0, 12.0).map(repr),
                              st.sampled_from(["100", "101", "-1", "x", "nan", "1e308"]))) for _ in range(width)]
        if width == 2 and chance(draw, 0.9):
            values[draw(st.integers(0, 1))] = "0"  # one wire at a time (the interlock)
        items.append(":".join([repr(t), *values]))
    return ",".join(items)


def set_values() -> st.SearchStrategy:
    sane = st.sampled_from(["h0_heating_W_m2K=30", "M_SF_Nm=0.02", "C_DF_heating_Nms=0.05", "V_H_V=6",
                            "friction_sticking=initial-only", "spring_init=given", "T_amb_C=30", "K_P_per_rad=100",
                            "h0_heating_W_m2K=1e4", "V_H_V=100", "spring_K_N_m=1e6", "inertia_kg_m2=1e-7",
                            "eps_R=0.2", "D_M_Pa=1e8", "pwm_period_s=0.5"])
    name = st.one_of(st.sampled_from(FIELDS), st.sampled_from(OPTION_NAMES), st.sampled_from(["bogus", "", "="]))
    value = st.one_of(st.sampled_from(["0", "1", "-5", "1e6", "1e-9", "20", "0.02", "equilibrium", "given", "rate",
                                       "initial-only", "true", "false", "x", "", "nan", "inf", "1e308"]),
                      st.floats(-10.0, 200.0).map(repr))
    return mostly(sane, st.builds(lambda n, sep, v: f"{n}{sep}{v}", name, st.sampled_from(["=", "=", "=", ":"]),
                                  value), 0.3)


@st.composite
def simulate_cases(draw) -> Case:
    inputs: dict[str, str | None] = {"d": None}
    argv = ["simulate", "--no-progress"]
    outputs: list[str] = []

    def maybe(flag: str, strategy, p: float = 0.5) -> None:
        if chance(draw, p):
            argv.extend([flag, draw(strategy)])

    maybe("--params", mostly(st.sampled_from(["paper2010", "paper2010-table2", "authors2020", "p.toml"]),
                             st.sampled_from(["linear-bias-spring", "", "nosuch", "d", "missing.toml"]), 0.2), 0.4)
    if "p.toml" in argv:
        inputs["p.toml"] = draw(parameter_file())
    for _ in range(draw(mostly(st.integers(0, 1), st.integers(2, 3), 0.2))):
        argv.extend(["--set", draw(set_values())])
    maybe("--scenario", mostly(st.sampled_from(SCENARIOS), st.sampled_from(["nosuch-v1", ""])), 0.1)
    strategy = draw(mostly(st.sampled_from(["open-loop", "independent", "cooperative"]), st.sampled_from(["sideways", ""])))
    if "--scenario" not in argv or chance(draw, 0.1):
        argv.extend(["--strategy", strategy])
        if strategy == "open-loop" or chance(draw, 0.1):
            argv.extend([draw(mostly(st.just("--voltage"), st.sampled_from(["--duty", "--current"]), 0.3)),
                         draw(program_text())])
        if strategy != "open-loop" or chance(draw, 0.1):
            argv.extend(["--profile", draw(profile_text())])
    if "--scenario" not in argv or chance(draw, 0.2):
        maybe("--t-end", T_END, 0.8)
    if "--t-end" not in argv and "--scenario" not in argv:
        argv.extend(["--t-end", repr(draw(st.floats(0.001, 3.0)))])  # keep the default 20 s for scenarios only
    maybe("--dt", DT, 0.3)
    maybe("--method", mostly(st.sampled_from(list(INTEGRATORS)), st.sampled_from(["RK4", "midpoint"])), 0.3)
    maybe("--pwm", mostly(st.sampled_from(list(PWM_MODELS)), st.sampled_from(["Exact", "edges"])), 0.2)
    maybe("--output-interval", OUTPUT_INTERVAL, 0.3)
    maybe("--tol-deg", TOLERANCE, 0.15)
    maybe("--tol-m", TOLERANCE, 0.1)
    maybe("--hold-s", TOLERANCE, 0.15)
    for flag, sane, nasty in (("--out", ["r.csv", "r.parquet", "r.mat", "r.CSV"], ["r.txt", "d", "no/r.csv", ""]),
                              ("--summary", ["s.json"], ["s.txt", "d", "r.provenance.json", "no/s.json"]),
                              ("--plot", ["p.png", "p.svg"], ["p.foo", "d"])):
        if chance(draw, (0.05 if flag == "--plot" else 0.4)):
            name = draw(mostly(st.sampled_from(sane), st.sampled_from(nasty)))
            argv.extend([flag, name])
            outputs.append(name)
    if chance(draw, 0.05):
        name = draw(st.sampled_from(["old.json", "nothing.json", "d", "old.csv"]))
        argv.extend(["--from", name])
        if name == "old.json":
            inputs[name] = draw(st.sampled_from(['{"provenance": {"run": {"schema": 1}}}', "{", "[]", '{"a": 1}']))
    if chance(draw, 0.02):
        argv.append(draw(st.sampled_from(["--bogus", "extra", "--help"])))
    if "--help" in argv:
        return Case(argv, inputs)
    return Case(argv, inputs, tuple(o for o in outputs if o.lower().endswith((".csv", ".parquet", ".mat", ".json",
                                                                                ".png", ".svg"))))


@st.composite
def parameter_file(draw) -> str:
    """A parameter file: a whole set, a base and changes, or broken TOML."""
    kind = draw(mostly(st.sampled_from(["whole", "base"]), st.sampled_from(["broken", "empty", "partial"]), 0.25))
    if kind == "broken":
        return draw(st.sampled_from(["[", "a = ", 'base = "paper2010"\nbase = "x"', "\x00", "x = [1, 'a']"]))
    if kind == "empty":
        return ""
    p = get(draw(st.sampled_from(PARAM_SETS)))
    lines = p.to_toml().splitlines()
    if kind == "whole":
        k = draw(st.integers(0, len(lines) - 1))
        lines[k] = draw(mostly(st.just(lines[k]), st.sampled_from(["", f"{FIELDS[k % len(FIELDS)]} = \"x\"",
                                                                  "bogus = 1", f"{lines[k].split('=')[0]}= -1e308",
                                                                  f"{lines[k].split('=')[0]}= true"]), 0.5))
        return "\n".join(lines) + "\n"
    if kind == "partial":
        return "\n".join(ln for ln in lines if draw(st.booleans())) + "\n"
    base = draw(mostly(st.sampled_from(["paper2010", "paper2010-table2", "authors2020"]),
                       st.sampled_from(["linear-bias-spring", "nosuch", ""])))
    changes = [draw(set_values()).replace("=", " = ", 1).replace(":", " = ", 1) for _ in range(draw(st.integers(0, 3)))]
    mech = draw(mostly(st.sampled_from(["", 'mechanism = "joint"']),
                       st.sampled_from(['mechanism = "linear-bias-spring"', 'mechanism = "x"'])))
    return "\n".join([f'base = "{base}"', mech, *[c if '"' in c else _quoted(c) for c in changes]]) + "\n"


def _quoted(assignment: str) -> str:
    """``NAME = VALUE`` with a non-number VALUE quoted (so that the TOML parses more often)."""
    name, _, value = assignment.partition(" = ")
    try:
        float(value)
        return f"{name} = {value}" if value.strip() not in ("nan", "inf", "-inf", "") else f'{name} = "{value}"'
    except ValueError:
        return f'{name} = "{value}"'


@st.composite
def params_cases(draw) -> Case:
    text = draw(parameter_file())
    inputs = {"p.toml": text, "d": None}
    if draw(st.booleans()):
        out = draw(st.sampled_from(["o.toml", "d", "no/o.toml", "o.txt"]))
        argv = ["params", "p.toml", "--out", out]
        return Case(argv, inputs, (out,) if out.endswith(".toml") else ())
    if draw(st.booleans()):
        return Case(["params", "p.toml", *sum((["--set", draw(set_values())] for _ in range(2)), [])], inputs)
    return Case(["simulate", "--params", "p.toml", "--profile", draw(profile_text()), "--t-end", "0.5",
                 "--no-progress"], inputs)


T_END_TOML = ["0.5", "1.0", "2", "1e308", "-1", '"x"', "1e10", "nan"]
VARIED_VALUES = ["1.0", "60.0", "0.01", "-5.0", '"x"', "1e308"]


@st.composite
def sweep_cases(draw) -> Case:
    base = [f'params = "{draw(mostly(st.sampled_from(["paper2010", "paper2010-table2"]), st.sampled_from(PARAM_SETS + ["nosuch"])))}"']
    strategy = draw(mostly(st.sampled_from(["open-loop", "cooperative", "independent"]), st.just("x")))
    base.append(f'strategy = "{strategy}"')
    if strategy == "open-loop" or draw(st.booleans()):
        base.append(f'voltage = "{draw(program_text())}"')
    if strategy != "open-loop" or draw(st.booleans()):
        base.append(f'profile = "{draw(profile_text())}"')
    base.append("t_end_s = " + draw(mostly(st.sampled_from(T_END_TOML[:3]), st.sampled_from(T_END_TOML[3:]))))
    if draw(st.booleans()):
        base.append("dt_s = " + draw(mostly(st.sampled_from(["1e-3", "5e-4"]), st.sampled_from(["0", "1.5e-10", "true"]))))
    mode = draw(mostly(st.sampled_from(["grid", "list", "random", "lhs"]), st.just("nope")))
    sweep = [f'mode = "{mode}"']
    if mode in ("random", "lhs") or chance(draw, 0.05):
        sweep += ["samples = " + draw(mostly(st.sampled_from(["1", "3", "5"]), st.sampled_from(["0", "-2", "1e9", "2.5"]))),
                  "seed = " + draw(mostly(st.sampled_from(["1", "7"]), st.sampled_from(["-1", '"x"'])))]
    name = draw(mostly(st.sampled_from(["h0_heating_W_m2K", "M_SF_Nm", "C_DF_heating_Nms"]),
                       st.sampled_from(["t_end_s", "dt_s", "bogus", "strategy", "params"])))
    values = draw(mostly(st.sampled_from(["60.0", "0.01", "0.05"]), st.sampled_from(VARIED_VALUES)))
    sane = {"grid": [f"{name} = [{values}, 0.02]", f"{name} = {{start = 0.01, stop = 0.05, num = 3}}",
                     '[vary.h0]\nfields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"]\nvalues = [60.0, 65.0]'],
            "list": [f"{name} = [{values}, 0.02]"],
            "random": [f"{name} = {{min = 0.01, max = 0.05}}"], "lhs": [f"{name} = {{min = 0.01, max = 0.05}}"]}
    nasty = ["", f'{name} = "x"', f"{name} = {{start = 0.01, stop = 0.05, num = 100000000}}",
             f"{name} = {{min = 0.01, max = -1}}", f"{name} = {{min = 0.01, max = 1e308}}", f"{name} = []"]
    vary = draw(mostly(st.sampled_from(sane.get(mode, nasty)), st.sampled_from(nasty)))
    text = "[base]\n" + "\n".join(base) + "\n[sweep]\n" + "\n".join(sweep) + "\n[vary]\n" + vary + "\n"
    out = draw(mostly(st.just("t.parquet"), st.sampled_from(["t.csv", "d", "no/t.parquet"])))
    argv = ["sweep", "s.toml", "--out", out, "--workers", "1"]
    outputs = [out]
    if chance(draw, 0.2):
        mat = draw(st.sampled_from(["t.mat", "t.txt", "d"]))
        argv += ["--mat", mat]
        outputs.append(mat)
    return Case(argv, {"s.toml": text, "d": None}, tuple(o for o in outputs if o.endswith((".parquet", ".mat"))))


@st.composite
def strain_file(draw) -> str:
    """A strain-temperature file: a sane cycle (with heating first) with some damage."""
    n = draw(mostly(st.integers(20, 60), st.integers(0, 19), 0.2))
    half = max(1, n // 2)
    rows = []
    for i in range(n):
        T = 30 + 110 * (i / half if i < half else max(0.0, 1 - (i - half) / max(1, n - half)))
        heating = i < half
        mid = 90 if heating else 60
        e = 0.04 * (1 - 1 / (1 + math.exp(-(T - mid) / 5)))
        rows.append([f"{T:.3f}", f"{e:.6f}", "100"])
    damage = draw(mostly(st.just("none"), st.sampled_from(["reverse", "flat", "nan", "text", "percent", "columns",
                                                          "unsorted", "header", "mpa_pa"]), 0.5))
    if damage == "reverse":
        rows = rows[::-1]
    elif damage == "flat":
        rows = [[r[0], "0.02", r[2]] for r in rows]
    elif damage in ("nan", "text") and rows:
        k = draw(st.integers(0, len(rows) - 1))
        rows[k][draw(st.integers(0, 2))] = "nan" if damage == "nan" else "abc"
    elif damage == "percent":
        rows = [[r[0], str(float(r[1]) * 100), r[2]] for r in rows]
    elif damage == "columns" and rows:
        rows[draw(st.integers(0, len(rows) - 1))].append("7")
    elif damage == "unsorted":
        rows = draw(st.permutations(rows))
    elif damage == "mpa_pa":
        rows = [[r[0], r[1], "1e8"] for r in rows]
    head = ["temperature strain stress"] if damage == "header" else []
    return "\n".join(head + [" ".join(r) for r in rows]) + "\n"


@st.composite
def angle_file(draw, heating: bool = False) -> str:
    """A joint angle curve; a heating curve's voltage mostly stays on (switching it off is refused)."""
    n = draw(st.integers(0, 25))
    voltage = draw(st.booleans())
    off = n if heating and chance(draw, 0.8) else draw(st.integers(0, max(0, n - 1)))
    rows = ["time_s,angle_deg" + (",voltage_V" if voltage else "")]
    for i in range(n):
        t = 0.1 * i
        angle = -40 + 10 * (1 - math.exp(-t))
        rows.append(f"{t:.2f},{angle:.3f}" + (f",{8 if i < off else 0}" if voltage else ""))
    damage = draw(st.sampled_from(["none", "none", "time", "nan", "noheader", "range"]))
    if damage == "time" and n > 3:
        rows[3] = rows[3].replace("0.20", "0.05", 1)
    elif damage == "nan" and n > 2:
        rows[2] = "0.1,nan" + (",8" if voltage else "")
    elif damage == "noheader":
        rows = rows[1:]
    elif damage == "range" and n > 2:
        rows[2] = "0.1,400" + (",8" if voltage else "")
    return "\n".join(rows) + "\n"


@st.composite
def identify_cases(draw) -> Case:
    outputs = []
    extra = []
    for flag, name in (("--out", "fit.toml"), ("--report", "fit.json"), ("--plot", "fit.png")):
        if chance(draw, (0.1 if flag == "--plot" else 0.3)):
            choice = draw(mostly(st.just(name), st.sampled_from(["d", "fit.txt"])))
            extra += [flag, choice]
            outputs.append(choice)
    if chance(draw, 0.3):
        extra += ["--params", draw(mostly(st.sampled_from(["paper2010", "authors2020"]),
                                          st.sampled_from(PARAM_SETS + ["nosuch", ""])))]
    keep = tuple(o for o in outputs if o != "d" and not o.endswith(".txt"))
    if chance(draw, 0.8):
        k = draw(st.integers(1, 3))
        inputs = {f"k{i}.txt": draw(strain_file()) for i in range(k)}
        argv = ["identify", "kinetics", *inputs, "--no-progress", "--no-loo"]
        if draw(st.booleans()):
            argv += ["--stress", draw(st.sampled_from(["mean", "row", "max"]))]
        if chance(draw, 0.2):
            argv += ["--validate", draw(st.sampled_from(["k0.txt", "missing.txt", "d"]))]
        return Case(argv + extra, {**inputs, "d": None}, keep)
    inputs = {"h.csv": draw(angle_file(heating=True)), "c.csv": draw(angle_file()), "d": None}
    argv = ["identify", "joint", "--heating", "h.csv", "--cooling", "c.csv", "--no-progress"]
    # --heat-s is for a cooling curve without a voltage column (one that contradicts it is refused)
    if chance(draw, 0.2 if "voltage_V" in inputs["c.csv"] else 0.5):
        argv += ["--heat-s", draw(st.sampled_from(["0.5", "1", "99", "-1", "nan", "x"]))]
    if chance(draw, 0.3):
        argv += ["--cooling-voltage", draw(st.sampled_from(["8", "0", "101", "nan"]))]
    return Case(argv + extra, inputs, keep)
