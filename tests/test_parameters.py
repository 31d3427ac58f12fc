"""Parameter sets: validation messages, TOML round trip, overrides."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from smafinger.parameters import ParameterError, changed_from_named, get, load_toml, resolve
from smafinger.parameters.base import ParameterSet
from smafinger.parameters.options import SpringInit
from smafinger.model.build import initial_spring_elongations


def test_named_sets_cite_their_source():
    for name in ("paper2010", "authors2020", "paper2010-table2"):
        p = get(name)
        assert p.name == name and "20" in p.source


def test_paper_values():
    p = get("paper2010")
    assert (p.h0_heating_W_m2K, p.h0_cooling_W_m2K, p.C_DF_heating_Nms, p.C_DF_cooling_Nms) == (20, 41, 0.03, 0.09)
    assert (p.K_P_per_rad, p.K_V_s_per_rad, p.K_I_per_rad_s, p.controller_update_s) == (3000, 3000, 50, 0.01)
    a = get("authors2020")
    assert (a.resistance_ohm_per_m, a.M_SF_Nm, a.T_amb_C, a.T_init_C) == (8.66, 0.011, 60, 60)
    assert (a.K_P_per_rad, a.K_V_s_per_rad, a.K_I_per_rad_s, a.controller_update_s) == (8000, 5000, 30, 0)


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_out_of_range_value_refused_with_field_value_and_range(v):
    lo, hi = 0.0, 1e4
    if math.isfinite(v) and lo <= v <= hi:
        assert get("paper2010").replace(h0_heating_W_m2K=v).h0_heating_W_m2K == v
        return
    with pytest.raises(ParameterError) as exc:
        get("paper2010").replace(h0_heating_W_m2K=v)
    msg = str(exc.value)
    assert "h0_heating_W_m2K" in msg and "[0, 10000]" in msg


def test_cross_checks():
    with pytest.raises(ParameterError, match="A_S0_C"):
        get("paper2010").replace(A_S0_C=120.0)
    with pytest.raises(ParameterError, match="must exceed spring_free_length_m"):
        get("paper2010").replace(spring_length_upper_m=5e-3, spring_init="given")
    with pytest.raises(ParameterError, match="stress_law"):
        get("paper2010").replace(stress_law="magic")
    # a major loop empty at zero stress (the kinetics refuse it; the set ran it, with 406 loop
    # violations and no warning: found by review)
    with pytest.raises(ParameterError, match="A_F0_C = 110.0 must exceed M_S0_C = 115.0"):
        get("paper2010").replace(M_S0_C=115.0)
    with pytest.raises(ParameterError, match="A_S0_C = 55.0 must exceed M_F0_C = 60.0"):
        get("paper2010").replace(A_S0_C=55.0)


def test_an_upper_spring_length_the_equilibrium_start_ignores_is_refused():
    p = get("paper2010")
    assert p.spring_init == SpringInit.EQUILIBRIUM
    with pytest.raises(ParameterError, match="spring_length_upper_m = 0.018 has no effect"):
        p.replace(spring_length_upper_m=0.018)
    given = p.replace(spring_length_upper_m=0.018, spring_init="given")
    assert initial_spring_elongations(given)[0] == pytest.approx(0.018 - p.spring_free_length_m)
    assert p.replace(spring_length_upper_m=p.spring_length_upper_m) == p  # unchanged: accepted
    with pytest.raises(ParameterError, match="has no effect"):  # the same through --set
        given.with_overrides(["spring_init=equilibrium", "spring_length_upper_m=0.0175"])


def test_the_ignored_spring_length_edited_in_a_named_sets_file_is_refused(tmp_path):
    """Found by review: the file `params paper2010 --out` writes, with spring_length_upper_m
    edited, ran unchanged while the summary named the field changed."""
    p = get("paper2010")
    f = tmp_path / "p.toml"
    p.save(f)
    assert load_toml(f, get) == p  # unedited: accepted
    f.write_text(f.read_text().replace(f"spring_length_upper_m = {p.spring_length_upper_m!r}",
                                       "spring_length_upper_m = 0.02"))
    with pytest.raises(ParameterError, match="spring_length_upper_m = 0.02 has no effect"):
        load_toml(f, get)
    f.write_text(f.read_text().replace('name = "paper2010"', 'name = "mine"'))
    assert load_toml(f, get).spring_length_upper_m == 0.02  # a set of the user's own: no reference


@pytest.mark.parametrize("value", [np.float32(6.0), np.int64(6), np.float64(6.0), 6])
def test_numpy_and_whole_numbers_are_stored_as_floats(value):
    """Found by review: numpy scalars were refused as 'not a number'."""
    v = get("paper2010").replace(V_H_V=value).V_H_V
    assert type(v) is float and v == 6.0


@pytest.mark.parametrize("value, needle", [
    (10 ** 400, "V_H_V = 1000000000"),  # was an internal OverflowError
    (np.True_, "is not a number"),
    (True, "is not a number"),
    ("6", "is not a number"),
])
def test_values_that_are_no_numbers_are_refused_naming_the_field(value, needle):
    with pytest.raises(ParameterError, match=needle):
        get("paper2010").replace(V_H_V=value)


@pytest.mark.parametrize("text, needle", [
    ('base = ["paper2010"]\n', "base = \\['paper2010'\\] is not a string"),
    ('mechanism = ["joint"]\n', "mechanism = \\['joint'\\] is not a string"),
    ('base = "paper2010.toml"\n', "base = 'paper2010.toml': unknown parameter set 'paper2010.toml' \\(known: "),
])
def test_a_files_base_and_mechanism_are_names(tmp_path, text, needle):
    f = tmp_path / "p.toml"
    f.write_text(text)
    with pytest.raises(ParameterError, match=needle) as info:
        load_toml(f, get)
    assert ".toml file" not in str(info.value)  # base takes no file


def test_a_set_changed_under_its_name_lists_what_changed():
    p = get("paper2010")
    assert changed_from_named(p) == ()
    q = p.with_overrides(["K_P_per_rad=4000", "stress_law=algebraic", "h0_heating_W_m2K=20"])  # h0: its own value
    assert q.name == "paper2010" and changed_from_named(q) == ("K_P_per_rad", "stress_law")
    assert changed_from_named(q.replace(name="mine")) == ()  # no set of that name to differ from
    assert changed_from_named(get("linear-bias-spring").replace(V_H_V=3.0)) == ("V_H_V",)


def test_frozen():
    p = get("paper2010")
    with pytest.raises(Exception):
        p.h0_heating_W_m2K = 3.0  # type: ignore[misc]


def test_no_defaults():
    with pytest.raises(TypeError):
        ParameterSet()  # type: ignore[call-arg]


def test_overrides():
    p = get("paper2010").with_overrides(["h0_heating_W_m2K=25", "controller_in_cooling=false", "stress_law=algebraic"])
    assert p.h0_heating_W_m2K == 25.0 and p.controller_in_cooling is False and p.stress_law == "algebraic"
    with pytest.raises(ParameterError, match="NAME=VALUE"):
        get("paper2010").with_overrides(["h0"])
    with pytest.raises(ParameterError, match="unknown parameter"):
        get("paper2010").with_overrides(["nope=1"])
    with pytest.raises(ParameterError, match="not a number"):
        get("paper2010").with_overrides(["h0_heating_W_m2K=abc"])


def test_toml_round_trip(tmp_path):
    for name in ("paper2010", "authors2020"):
        p = get(name)
        f = tmp_path / f"{name}.toml"
        p.save(f)
        assert load_toml(f, get) == p
        assert resolve(str(f)) == p


def test_toml_with_base_and_errors(tmp_path):
    f = tmp_path / "fit.toml"
    f.write_text('base = "paper2010"\nh0_heating_W_m2K = 33.0\n')
    assert resolve(str(f)).h0_heating_W_m2K == 33.0
    f.write_text('base = "paper2010"\nh0_heating_W_m2K = -1.0\n')
    with pytest.raises(ParameterError, match="h0_heating_W_m2K"):
        resolve(str(f))
    f.write_text('h0_heating_W_m2K = 1.0\n')
    with pytest.raises(ParameterError, match="missing parameter"):
        resolve(str(f))
    f.write_text('base = "paper2010"\nfoo = 1.0\n')
    with pytest.raises(ParameterError, match="unknown parameter"):
        resolve(str(f))


@pytest.mark.parametrize("base", ['base = "paper2010"\n', None])
def test_an_option_given_twice_in_a_file_is_refused(tmp_path, base):
    """At the top level and in [options]: the top-level one used to win without a word, as in a
    full file (params --out) with one line added at its top (found by review)."""
    from smafinger.parameters.files import to_toml

    f = tmp_path / "p.toml"
    if base:
        f.write_text(base + 'hysteresis = "deadband"\n[options]\nhysteresis = "memory"\n')
    else:  # a whole set as params --out writes it, one line added at the top
        f.write_text('thermal_model = "two-node"\n' + to_toml(get("paper2010")))
    with pytest.raises(ParameterError, match=r"(hysteresis|thermal_model) is given twice, at the top level "
                                             r"\('(deadband|two-node)'\) and in \[options\]"):
        resolve(str(f))
    f.write_text('base = "paper2010"\nV_H_V = 6\n[options]\nV_H_V = 10\n')  # a parameter in [options]
    with pytest.raises(ParameterError, match=r"unknown option\(s\) in \[options\]: V_H_V"):
        resolve(str(f))


def test_a_given_length_taken_back_to_equilibrium_is_the_named_sets_and_a_record_is_kept(tmp_path):
    """Found by review: a given start with its own length, set back to equilibrium under the named
    set's name, was written by `params --out` and then refused when read back; refusing it instead
    broke a sweep over spring_init. The length equilibrium ignores now takes the named set's value,
    and a run's record (made before the refusal existed) replays as it ran."""
    from smafinger.parameters import from_dict

    p = get("paper2010")
    given = p.replace(spring_init="given", spring_length_upper_m=0.0176)
    back = given.replace(spring_init="equilibrium")
    assert back == p and back.spring_length_upper_m == p.spring_length_upper_m
    back.save(tmp_path / "b.toml")
    assert load_toml(tmp_path / "b.toml", get) == p  # reads back
    with pytest.raises(ParameterError, match="spring_length_upper_m = 0.0176 has no effect .* paper2010 has"):
        given.replace(spring_init="equilibrium", spring_length_upper_m=0.0176)  # asked for: refused
    ran = {"mechanism": "joint", **p.to_dict()}
    ran["spring_length_upper_m"] = 0.0176
    assert from_dict(ran, record=True).spring_length_upper_m == 0.0176  # as it ran: kept
    with pytest.raises(ParameterError, match="has no effect"):
        from_dict(ran)  # as a file's edit: refused


def test_one_string_where_a_list_belongs_is_a_list_of_one():
    """A string given where a list belongs was split into its letters: with_overrides("V_H_V=6")
    read the override 'V', select_tasks("joint") the mechanism 'j' (found by an API fuzz)."""
    from smafinger.bench.tasks import select_tasks
    from smafinger.control.params import controller_from
    from smafinger.paper.runner import select

    p = get("paper2010")
    assert p.with_overrides("V_H_V=6") == p.with_overrides(["V_H_V=6"]) and p.with_overrides("V_H_V=6").V_H_V == 6.0
    assert controller_from("pid", "K_P_per_q=3").K_P_per_q == 3.0
    assert select_tasks("joint") == select_tasks(("joint",))
    from smafinger.paper.overrides import Overrides

    assert Overrides.coerce("T_init_C=40") == Overrides.coerce(["T_init_C=40"])  # one rule everywhere
    assert [s.name for s in select("fig8-h0-60-upper-v1")] == ["fig8-h0-60-upper-v1"]


def test_a_parameter_file_of_changes_writes_an_option_by_its_label(tmp_path):
    """overrides_toml wrote an option member as a float ('stress_law = 0.0'), which the loader
    refuses (found by an API fuzz)."""
    from smafinger.parameters import resolve
    from smafinger.parameters.files import overrides_toml
    from smafinger.parameters.options import StressLaw

    path = tmp_path / "changed.toml"
    path.write_text(overrides_toml("paper2010", {"stress_law": StressLaw.ALGEBRAIC, "T_init_C": 30}, "a test"))
    q = resolve(str(path))
    assert q.options.stress_law == StressLaw.ALGEBRAIC and q.T_init_C == 30.0
