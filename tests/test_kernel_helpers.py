"""The kernel's small helpers: views without reference counting, the exponential integrator's phi functions."""

import math

import numpy as np
from hypothesis import given, strategies as st
from numba import njit

from smafinger.engine.integrators import phi12
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
