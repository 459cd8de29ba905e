"""The stall guard: one step-size collapse rule for the compiled IDA loop, the Python session and
the explicit methods (daeclear.engine.stall_guard)."""

from __future__ import annotations

import pytest

from daeclear.engine import stall_guard
from daeclear.engine.build import driver_files
from daeclear.engine.stall_guard import TINY_STEP_COUNT, TINY_STEP_GROWTH, TINY_STEP_REL, StallGuard


def test_count_tiny_steps_that_do_not_grow():
    guard = StallGuard()
    h = 0.5 * TINY_STEP_REL  # tiny at t = 1
    # the first step has no previous one to compare with (it counts as grown): then 20 tiny ones
    assert not any(guard.step(1.0, h) for _ in range(TINY_STEP_COUNT))
    assert guard.step(1.0, h)  # the TINY_STEP_COUNT-th counted
    assert guard.describe(1.0, h) == ("step size collapsed: 20 steps with |h| < max(1e-14*max(1,|t|), 0 s) that "
                                      "did not grow (last h=5e-15) at t=1.0")


def test_growing_steps_are_a_start_up_and_a_normal_step_resets():
    guard = StallGuard()
    h = 1e-30
    while h < TINY_STEP_REL:  # IDA's start-up doubling: tiny, but each step grows
        assert not guard.step(1.0, h)
        h *= 2.0
    assert guard.tiny == 0
    assert not any(guard.step(1.0, 1e-16) for _ in range(TINY_STEP_COUNT - 1))  # each one counted
    assert guard.tiny == TINY_STEP_COUNT - 1
    assert not guard.step(1.0, 1e-3)  # a normal step
    assert guard.tiny == 0
    grown = StallGuard()
    grown.step(1.0, 1e-16)
    grown.step(1.0, 1e-16)
    assert grown.tiny == 1
    grown.step(1.0, 1e-16 * TINY_STEP_GROWTH * 1.01)  # grew by more than the factor: not counted
    assert grown.tiny == 1


def test_an_absolute_stall_step_and_its_normal_step_margin():
    guard = StallGuard(stall_step=1e-12, count=3)
    assert not guard.step(1.0, 5e-13) and not guard.step(1.0, 5e-13)  # the first is not compared
    assert guard.tiny == 1
    assert not guard.step(1.0, 5e-11)  # above the threshold, below 100x: neither counted nor a reset
    assert guard.tiny == 1
    assert not guard.step(1.0, 5e-13)
    assert guard.step(1.0, 5e-13)  # the third counted tiny step
    guard.reset()
    assert guard.tiny == 0 and guard.h_prev == 0.0
    guard.step(1.0, 5e-13)
    guard.step(1.0, 5e-13)
    assert guard.tiny == 1
    assert not guard.step(1.0, 2e-10) and guard.tiny == 0  # 100x the threshold: a normal step


def test_the_compiled_loop_takes_its_numbers_from_the_module():
    """The C driver defines none of the numbers itself: they come from the build's -D flags."""
    source = "".join(path.read_text() for path in driver_files("ida_driver.c"))  # the driver and its parts
    assert "#define DC_TINY_REL" not in source and "#error" in source
    defines = dict(flag[2:].split("=", 1) for flag in stall_guard.c_defines())
    assert float(defines["DC_TINY_REL"]) == TINY_STEP_REL
    assert int(defines["DC_TINY_MAX"]) == TINY_STEP_COUNT
    assert float(defines["DC_TINY_GROWTH"]) == TINY_STEP_GROWTH
    assert float(defines["DC_NORMAL_STEP_FACTOR"]) == stall_guard.NORMAL_STEP_FACTOR


def stalled_advance(backend: str):
    """The Fig. 4.15 slider-crank's first advance with every step below 1 s tiny, five ending it."""
    import numpy as np

    import daeclear as dc
    from daeclear.engine.ida_session import open_session
    from daeclear.solvers.tolerances import tolerance_vector

    model = dc.assemble(dc.mechanisms.slider_crank())
    session = open_session(model.functions, backend=backend, rtol=1e-6, atol=tolerance_vector(model, 1e-6, None),
                           parameters=model.parameter_values)
    try:
        y0, yp0 = model.initial_state(session=session)
        session.set_stall(1.0, 5)
        session.reinit(0.0, y0, yp0, [False] * len(model.terms), [np.zeros(t.n_params) for t in model.terms])
        return session.advance(0.01)
    finally:
        session.close()


def test_both_ida_backends_stop_at_the_same_step_with_the_same_words():
    """After IDA's start-up doubling (growing steps do not count), five steps that stopped growing
    end the compiled loop and the Python session alike."""
    c, py = stalled_advance("c"), stalled_advance("python")
    for advance in (c, py):
        assert advance.status == "error" and advance.flag_name == "DC_STEP_COLLAPSE"
        assert advance.message.startswith("step size collapsed: 5 steps with |h| < max(1e-14*max(1,|t|), 1 s) "
                                          "that did not grow")
    assert c.t == pytest.approx(py.t, rel=1e-6)
    assert c.step_t.size == py.step_t.size
