"""Channels computed when read: a run's (or a result file's) states, and what computes its channels.

A run stores its states only: the times ``t``, the states ``y`` and, per point, the switch vector of its
segment (the outputs' ``switch`` input). A run kept in memory stores IDA's own ``y``, whose multipliers
IDA does not converge: they and ``yp`` are made consistent (the run's consistency pass) at the first read
of either. The channels are one function of these, the model's generated output function, so
:class:`LazyChannels` evaluates them all in one vectorised call at the first read and keeps them, equal
bit for bit to what the run would have computed point by point (tests/test_lazy_channels.py).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.values import readonly

__all__ = ["Consistent", "Evaluate", "LazyChannels", "rebuilt_evaluator"]

#: Computes every channel at the rows of (t, y, yp, switch): name -> array of the rows.
Evaluate = Callable[[NDArray, NDArray, NDArray, NDArray], Mapping[str, NDArray]]
#: (y, yp) at the rows of (t, y, switch): the run's consistency pass (multipliers and accelerations from q and v).
Consistent = Callable[[NDArray, NDArray, NDArray], tuple[NDArray, NDArray]]


class LazyChannels:
    """The channels of stored states, computed at the first :meth:`values`.

    Parameters
    ----------
    names : sequence of str
        The channel names (known without computing them).
    evaluate : Evaluate
        Computes every channel at given rows (the model's output function).
    t, y, yp : arrays
        The stored states, time first; ``yp`` None: computed by ``consistent`` when first read
        (a file keeps t, y and the switch rows alone).
    switch : array, shape (n_times, n_switch)
        Each point's switch vector (its segment's contact terms).
    consistent : Consistent, optional
        Makes the states consistent: computes ``yp`` when it is None (and ``y``'s multipliers when raw).
    raw : bool
        ``y`` holds IDA's own multipliers (a run kept in memory, ``yp`` None): ``y`` too is read
        from ``consistent``.
    recomputed : slice
        The columns of ``y`` the consistency pass recomputes (the multipliers); :meth:`state_column`
        reads the others without it.
    values : mapping, optional
        The channels when already computed (e.g. for the run's physics checks).
    rebuildable : bool or callable returning bool
        Whether ``evaluate`` can be made again from the result's parameters alone (the scene
        rebuilt from its description): a file may then store the states without the channels
        (a callable is asked at the first :meth:`can_rebuild`).
    """

    def __init__(self, names: Sequence[str], evaluate: Evaluate, t: NDArray, y: NDArray, yp: NDArray | None,
                 switch: NDArray, *, consistent: Consistent | None = None, raw: bool = False,
                 recomputed: slice = slice(0, 0), values: Mapping[str, NDArray] | None = None,
                 rebuildable: bool | Callable[[], bool] = False) -> None:
        if switch.ndim != 2 or switch.shape[0] != t.shape[0]:
            raise ValueError(f"LazyChannels: switch has shape {switch.shape}, must be (n_times={t.shape[0]}, "
                             "n_switch).")
        self.names = tuple(names)
        self.evaluate = evaluate
        if yp is None and consistent is None:
            raise ValueError("LazyChannels: yp is None and no consistent states compute it.")
        if raw and yp is not None:
            raise ValueError("LazyChannels: raw states come without yp (both are made consistent together).")
        self.t, self._y, self._yp, self.switch = t, y, yp, readonly(switch)
        self.consistent, self.raw, self.recomputed = consistent, raw, recomputed
        self._rebuildable = rebuildable
        self._values = None if values is None else {n: readonly(values[n]) for n in self.names}

    def _make_consistent(self) -> None:
        """The run's consistency pass over every row: yp, and y's multipliers when raw."""
        assert self.consistent is not None
        y, yp = self.consistent(self.t, self._y, self.switch) if self.t.size else (self._y, np.zeros(self._y.shape))
        if self.raw:
            self._y, self.raw = readonly(y), False
        self._yp = readonly(yp)

    @property
    def y(self) -> NDArray:
        """The states: stored, or (raw) made consistent at the first read."""
        if self.raw:
            self._make_consistent()
        return self._y

    @property
    def stored_y(self) -> NDArray:
        """The states as stored, without the consistency pass: while :attr:`raw`, IDA's own rows (their
        :attr:`recomputed` columns, the multipliers, not converged)."""
        return readonly(self._y)

    def row(self, i: int) -> NDArray:
        """Row ``i`` of :attr:`y`: while raw, that row alone made consistent (the pass treats every row on
        its own, so it is bit for bit the row of the whole pass)."""
        if not self.raw:
            return self._y[i]
        assert self.consistent is not None
        k = range(self.t.size)[i]  # an IndexError beyond the rows, as y[i]
        rows = slice(k, k + 1)
        return readonly(self.consistent(self.t[rows], self._y[rows], self.switch[rows])[0][0])

    def state_column(self, j: int) -> NDArray:
        """Column ``j`` of the states: a kept column of raw states as stored (the pass leaves it unchanged)."""
        if self.raw and not self.recomputed.start <= j < self.recomputed.stop:
            return readonly(self._y[:, j])
        return self.y[:, j]

    @property
    def yp(self) -> NDArray:
        """The states' derivatives: stored, or computed at the first read (the run's consistency pass)."""
        if self._yp is None:
            self._make_consistent()
        assert self._yp is not None
        return self._yp

    @property
    def has_yp(self) -> bool:
        """Whether ``yp`` is at hand (stored or computed already)."""
        return self._yp is not None

    def can_rebuild(self) -> bool:
        """Whether the channels can be made again from the result's parameters alone (see above)."""
        if not isinstance(self._rebuildable, bool):
            self._rebuildable = bool(self._rebuildable())
        return self._rebuildable

    @property
    def computed(self) -> bool:
        """Whether the channels have been computed."""
        return self._values is not None

    def values(self) -> dict[str, NDArray]:
        """Every channel (read-only arrays, first dimension n_times), computed at the first call."""
        if self._values is None:
            if self.t.size:
                out = self.evaluate(self.t, self.y, self.yp, self.switch)
                self._values = {name: readonly(np.ascontiguousarray(out[name])) for name in self.names}
            else:
                self._values = {name: readonly(np.zeros(0)) for name in self.names}
        return self._values

    def __getstate__(self) -> dict[str, Any]:
        """Pickled (a result sent between processes: sweeps, parallel studies) with its channels and yp
        computed, without what computes them (the model's compiled functions stay in this process)."""
        self.values()
        state = dict(self.__dict__)
        state.update(_yp=self.yp, evaluate=None, consistent=None, _rebuildable=self.can_rebuild())
        return state

    def take(self, rows: Any) -> LazyChannels:
        """The channels of some rows (an index or a mask): computed ones cut, the others still lazy."""
        values = None if self._values is None else {n: v[rows] for n, v in self._values.items()}
        yp = None if self._yp is None else self._yp[rows]
        return LazyChannels(self.names, self.evaluate, self.t[rows], self._y[rows], yp, self.switch[rows],
                            consistent=self.consistent, raw=self.raw, recomputed=self.recomputed, values=values,
                            rebuildable=self._rebuildable)


def rebuilt_evaluator(parameters: Mapping[str, Any]) -> tuple[Evaluate, Consistent]:
    """:data:`Evaluate` and :data:`Consistent` for a result file's states: the model rebuilt from the
    file's parameters (scene description, formulation, run options) when they are first used
    (:mod:`daeclear.results.channel_eval`, imported then: reading a file loads no CasADi)."""
    def rebuilt() -> Any:
        from .channel_eval import evaluator_from_parameters

        return evaluator_from_parameters(parameters)

    def evaluate(t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> Mapping[str, NDArray]:
        return rebuilt().channels(t, y, yp, switch)

    def consistent(t: NDArray, y: NDArray, switch: NDArray) -> tuple[NDArray, NDArray]:
        return rebuilt().consistent(t, y, switch)

    return evaluate, consistent
