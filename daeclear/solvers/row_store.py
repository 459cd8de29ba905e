"""Rows appended in order and stored once: the columns of a run's points kept in memory.

A long run hands its points over in chunks. Keeping the chunks and joining them at the end writes every
point a second time into new memory (on a 64-link chain 0.7 GB, a fifth of the whole call, most of it
the kernel clearing new pages). A :class:`RowStore` keeps its rows in one array that grows in place
(``ndarray.resize``: ``realloc``, which moves a large block's pages without copying them), so each row
is copied once, into the array the Result keeps.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import DTypeLike, NDArray

#: rows of the first array (it doubles when full)
FIRST_ROWS = 1024


class RowStore:
    """Rows of shape ``tail`` (a row of a 2-D array: ``(width,)``; of a 1-D one: ``()``) and type
    ``dtype``, appended in order; :meth:`array` is the rows so far."""

    def __init__(self, tail: tuple[int, ...], dtype: DTypeLike = np.float64) -> None:
        self.n = 0
        self._rows = np.empty((FIRST_ROWS, *tail), dtype=dtype)

    def append(self, rows: NDArray) -> None:
        """Append ``rows`` (shape ``(k, *tail)``; a broadcast view writes its one row k times)."""
        k, size = len(rows), len(self._rows)
        if self.n + k > size:
            shape = (max(self.n + k, 2 * size), *self._rows.shape[1:])
            try:  # (no other name may hold the array here: resize counts its references)
                self._rows.resize(shape)  # refused while a view of it (an array() handed out) is alive
            except ValueError:
                grown = np.empty(shape, dtype=self._rows.dtype)
                grown[: self.n] = self._rows[: self.n]
                self._rows = grown
        self._rows[self.n: self.n + k] = rows
        self.n += k

    def array(self) -> NDArray:
        """The rows so far, shape ``(n, *tail)``: the store's array cut to them (its spare rows given back),
        or a view when an earlier one is alive. A later append then grows a copy."""
        if len(self._rows) > self.n:
            try:
                self._rows.resize((self.n, *self._rows.shape[1:]))
            except ValueError:
                return self._rows[: self.n]
        return self._rows
