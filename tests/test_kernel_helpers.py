"""The kernel's small helpers: views without reference counting, the exponential integrator's phi functions
and their reuse from step to step."""

import math

import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

from smafinger.engine.integrators import NO_DAMPING, damping_over, phi12
from smafinger.engine.unmanaged import unmanaged


@njit
def _fill_through_view(a, value):
    v = unmanaged(a)
    for i in range(v.shape[0]):
        for j in range(v.shape[1]):
            v[i, j] = value * (i + 1) + j
    return v.sum()


def test_unmanaged_view_writes_through_in_compiled_code():
    a = np.zeros((3, 4))
    total = _fill_through_view(a, 10.0)
    expected = np.array([[10.0 * (i + 1) + j for j in range(4)] for i in range(3)])
    np.testing.assert_array_equal(a, expected)  # the caller's array holds what the view wrote
    assert total == expected.sum()


def test_unmanaged_is_the_array_itself_in_python():
    a = np.arange(6.0).reshape(2, 3)
    assert unmanaged(a) is a


@given(st.floats(min_value=-60.0, max_value=0.0, allow_nan=False))
def test_phi12_matches_its_definitions(z):
    p1, p2 = phi12(z)
    if abs(z) > 1e-2:  # away from 0 the definitions themselves are accurate
        assert math.isclose(p1, math.expm1(z) / z, rel_tol=1e-12)
        assert math.isclose(p2, (math.expm1(z) - z) / (z * z), rel_tol=1e-9)
    else:  # near 0: their Taylor series (the next term is below 1e-11 there)
        assert math.isclose(p1, 1.0 + z / 2.0 + z ** 2 / 6.0 + z ** 3 / 24.0 + z ** 4 / 120.0, rel_tol=1e-10)
        assert math.isclose(p2, 0.5 + z / 6.0 + z ** 2 / 24.0 + z ** 3 / 120.0 + z ** 4 / 720.0, rel_tol=1e-10)
    assert 0.0 < p2 <= p1 <= 1.0  # both decrease from (1, 1/2) as z falls
    assert phi12.py_func(z) == (p1, p2)  # the compiled function is its Python source


@njit
def _damping_chain(cs, hs):
    """phi1, phi2 over a sequence of steps, each from the last step's Damping (as the kernel does)."""
    d = NO_DAMPING
    out = np.empty((len(cs), 3))
    for i in range(len(cs)):
        d = damping_over(cs[i], hs[i], d)
        out[i, 0], out[i, 1], out[i, 2] = d.z, d.phi1, d.phi2
    return out


@settings(deadline=None)  # the first example compiles _damping_chain
@given(st.lists(st.tuples(st.sampled_from([613.0, 1844.0, 0.0, 30.0]), st.sampled_from([5e-3, 1e-3, 2.5e-4])),
                min_size=1, max_size=30))
def test_damping_reused_is_phi12_of_every_step(steps):
    """Reusing the last step's factors while -c h repeats gives, at every step, phi12(-c h)
    bit for bit: the exponential integrator's results do not depend on the reuse."""
    cs, hs = (np.array(v) for v in zip(*steps))
    got = _damping_chain(cs, hs)
    for (c, h), (z, p1, p2) in zip(steps, got):
        assert z == -c * h and (p1, p2) == phi12(-c * h)


def test_damping_is_kept_while_z_repeats_and_made_anew_when_it_changes():
    d = damping_over.py_func(613.0, 5e-3, NO_DAMPING)
    assert d.z == -613.0 * 5e-3 and (d.phi1, d.phi2) == phi12.py_func(d.z)
    assert damping_over.py_func(613.0, 5e-3, d) is d  # the same z: the same record, no expm1
    e = damping_over.py_func(1844.0, 5e-3, d)
    assert e is not d and (e.phi1, e.phi2) == phi12.py_func(-1844.0 * 5e-3)
    assert math.isnan(NO_DAMPING.z) and damping_over.py_func(0.0, 5e-3, NO_DAMPING).z == 0.0  # NaN equals no z
