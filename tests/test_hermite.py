"""The one cubic Hermite interpolant (daeclear.engine.hermite): exact on cubics, value and
derivative, for one interval shared by all points and for one interval per point."""

from __future__ import annotations

import numpy as np
import pytest

from daeclear.engine.hermite import cubic_hermite

# two components: p(t) = c0 + c1 t + c2 t^2 + c3 t^3, with coefficients per component
C = np.array([[0.3, -1.2], [2.0, 0.5], [-0.7, 4.0], [1.1, -2.5]])


def p(t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, dtype=float)[..., None]
    return C[0] + C[1] * t + C[2] * t**2 + C[3] * t**3


def dp(t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, dtype=float)[..., None]
    return C[1] + 2 * C[2] * t + 3 * C[3] * t**2


def test_one_interval_reproduces_a_cubic_and_its_derivative():
    t0, t1 = 0.4, 1.9
    t = np.linspace(t0, t1, 17)
    y, yp = cubic_hermite(t0, p(t0), dp(t0), t1, p(t1), dp(t1), t, derivative=True)
    assert y.shape == yp.shape == (17, 2)
    np.testing.assert_allclose(y, p(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(yp, dp(t), rtol=0, atol=1e-12)
    # the ends are the given values exactly
    np.testing.assert_array_equal(y[0], p(t0))
    np.testing.assert_array_equal(y[-1], p(t1))
    # the value alone is the same array as with the derivative
    assert np.array_equal(cubic_hermite(t0, p(t0), dp(t0), t1, p(t1), dp(t1), t), y)


def test_one_interval_per_point():
    T = np.array([-1.0, -0.2, 0.5, 2.0])
    te = np.array([-0.9, -0.2, 0.1, 0.45, 1.3, 2.0])
    k = np.clip(np.searchsorted(T, te, side="left"), 1, T.size - 1)
    y, yp = cubic_hermite(T[k - 1], p(T[k - 1]), dp(T[k - 1]), T[k], p(T[k]), dp(T[k]), te, derivative=True)
    np.testing.assert_allclose(y, p(te), rtol=0, atol=1e-13)
    np.testing.assert_allclose(yp, dp(te), rtol=0, atol=1e-12)


def test_not_a_cubic_is_only_approximated():
    """A quartic is not reproduced: the test above could fail (the interpolant is no identity)."""
    t0, t1, t = 0.0, 1.0, np.array([0.25])
    q, dq = (lambda s: np.asarray(s, float)[..., None] ** 4), (lambda s: 4 * np.asarray(s, float)[..., None] ** 3)
    y = cubic_hermite(t0, q(t0), dq(t0), t1, q(t1), dq(t1), t)
    # Hermite error f - H = f''''/4! * (t - t0)^2 (t - t1)^2 = (0.25 * 0.75)^2 for f = t^4
    assert y[0, 0] == pytest.approx(0.25**4 - (0.25 * 0.75) ** 2, abs=1e-15)
