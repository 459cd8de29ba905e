"""The stall guard: when a run's step size has collapsed, one rule for every integrator.

A step of size ``h`` ending at ``t`` is *tiny* when ``|h| < max(TINY_STEP_REL * max(1, |t|),
stall_step)``. ``count`` tiny steps, each grown by at most ``TINY_STEP_GROWTH``, with no normal step
(at least the threshold, 100 times it with an absolute ``stall_step``) in between, end the run with a
clear message instead of creeping on. The C driver gets the numbers as ``-D`` defines (:func:`c_defines`).
"""

from __future__ import annotations

__all__ = ["TINY_STEP_COUNT", "TINY_STEP_GROWTH", "TINY_STEP_REL", "StallGuard", "c_defines"]

#: a step is tiny below TINY_STEP_REL * max(1, |t|) (about 45 ulps of t: the step cannot move t)
TINY_STEP_REL = 1e-14
#: tiny steps in a row that end the run (unless an absolute stall_step sets another count)
TINY_STEP_COUNT = 20
#: a tiny step that grew by more than this factor over the previous one is a start-up step, not a stall
TINY_STEP_GROWTH = 1.5
#: with an absolute stall_step, a step resets the count only from this multiple of the threshold on
NORMAL_STEP_FACTOR = 100.0


def c_defines() -> list[str]:
    """The guard's numbers as compiler defines of the C driver (``DC_TINY_REL``, ...)."""
    return [f"-DDC_TINY_REL={TINY_STEP_REL!r}", f"-DDC_TINY_MAX={TINY_STEP_COUNT}",
            f"-DDC_TINY_GROWTH={TINY_STEP_GROWTH!r}", f"-DDC_NORMAL_STEP_FACTOR={NORMAL_STEP_FACTOR!r}"]


class StallGuard:
    """Counts tiny steps (see the module docstring); :meth:`step` says when the run has stalled."""

    def __init__(self, stall_step: float = 0.0, count: int = TINY_STEP_COUNT) -> None:
        self.stall_step = float(stall_step)
        self.count = int(count)
        self.tiny = 0
        self.h_prev = 0.0

    def reset(self) -> None:
        """Forget the steps so far (a restart)."""
        self.tiny, self.h_prev = 0, 0.0

    def threshold(self, t: float) -> float:
        return max(TINY_STEP_REL * max(1.0, abs(t)), self.stall_step)

    def step(self, t: float, h: float) -> bool:
        """Record a new step of size ``h`` ending at ``t``; True when the run has stalled."""
        thr = self.threshold(t)
        if abs(h) >= (NORMAL_STEP_FACTOR * thr if self.stall_step > 0.0 else thr):
            self.tiny = 0
        elif abs(h) < thr and not abs(h) > TINY_STEP_GROWTH * abs(self.h_prev):
            self.tiny += 1
        self.h_prev = h
        return self.tiny >= self.count

    def describe(self, t: float, h: float) -> str:
        """What stalled, for the failure message (the compiled loop's words, csrc/ida_driver.c)."""
        return (f"step size collapsed: {self.tiny} steps with |h| < max({TINY_STEP_REL:g}*max(1,|t|), "
                f"{self.stall_step:g} s) that did not grow (last h={h:.3g}) at t={t!r}")
