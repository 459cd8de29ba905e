"""Shared fixtures."""

from __future__ import annotations

import signal

import numpy as np
import pytest

from daeclear.solvers import ida

_approx = pytest.approx
#: pytest.approx's default absolute tolerance: below about 1e-9 it, not ``rel``, decides the comparison.
APPROX_DEFAULT_ABS = 1e-12


def _approx_with_an_honest_tolerance(expected, rel=None, abs=None, nan_ok=False):
    """pytest.approx, refusing a comparison that its default abs=1e-12 would make 10 times wider than the
    rel asked for (a floor of 5.9e-12 compared at rel=1e-4 passed anything within 17 %): pass abs=."""
    if abs is None:
        try:
            values = expected.values() if isinstance(expected, dict) else expected
            flat = np.abs(np.asarray(values, dtype=float)).ravel()
        except (TypeError, ValueError):
            flat = np.zeros(0)
        widened = APPROX_DEFAULT_ABS / flat[flat > 0] if flat.size else np.zeros(0)
        if np.any((widened > 10 * (1e-6 if rel is None else rel)) & (widened > 1e-9)):
            raise ValueError(f"pytest.approx({expected!r}, rel={rel}): the default abs={APPROX_DEFAULT_ABS:g} makes "
                             f"this comparison up to {widened.max():.2g} relative; give abs= (abs=0.0 for rel alone).")
    return _approx(expected, rel=rel, abs=abs, nan_ok=nan_ok)


pytest.approx = _approx_with_an_honest_tolerance  # type: ignore[assignment]


@pytest.fixture
def plain_ida(monkeypatch: pytest.MonkeyPatch) -> str:
    """The compiled backend run as the python backend runs IDA (scikit-sundae sets neither hint):
    IDA's own Jacobian refresh and first step. Returns the linear solver to pass as well
    ("dense": SUNDIALS' LU of the whole matrix). Comparisons step for step with the python
    backend need all three."""
    monkeypatch.setattr(ida, "JACOBIAN_REFRESH", ida.IDA_JACOBIAN_REFRESH)
    monkeypatch.setattr(ida, "FIRST_STEP_ESTIMATE", False)
    return "dense"


@pytest.fixture
def ctrl_c_at_update(monkeypatch: pytest.MonkeyPatch):
    """``ctrl_c_at_update(n)``: the n-th progress update of a run raises KeyboardInterrupt (a Ctrl-C there);
    returns the count of updates so far (a one-element list)."""
    from daeclear.core.progress import Progress

    original = Progress.update

    def arm(n: int) -> list[int]:
        calls = [0]

        def update(self: Progress, t: float, note: str = "") -> None:
            calls[0] += 1
            if calls[0] == n:
                raise KeyboardInterrupt
            original(self, t, note)

        monkeypatch.setattr(Progress, "update", update)
        return calls

    return arm


@pytest.fixture
def sigint_as_a_terminal_sends_it():
    """Ctrl-C handled as Python does at a terminal, also when the suite was started in the background
    (``cmd &`` in a script: SIGINT ignored, which the child processes of these tests would inherit)."""
    ignored = signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    if ignored:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    if ignored:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
