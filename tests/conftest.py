"""Shared fixtures."""

from __future__ import annotations

import pytest

from daeclear.solvers import ida


@pytest.fixture
def plain_ida(monkeypatch: pytest.MonkeyPatch) -> str:
    """The compiled backend run as the python backend runs IDA (scikit-sundae sets neither hint):
    IDA's own Jacobian refresh and first step. Returns the linear solver to pass as well
    ("dense": SUNDIALS' LU of the whole matrix). Comparisons step for step with the python
    backend need all three."""
    monkeypatch.setattr(ida, "JACOBIAN_REFRESH", ida.IDA_JACOBIAN_REFRESH)
    monkeypatch.setattr(ida, "FIRST_STEP_ESTIMATE", False)
    return "dense"
