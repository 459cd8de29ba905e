"""Rows appended in order into one array per column: the columns of a run's points kept in memory.

A long run hands its points over in chunks. Keeping the chunks and joining them at the end writes every
point twice into new memory (on a 64-link chain 0.7 GB, a fifth of the whole call, most of it the kernel
clearing new pages). A :class:`RowStore` appends each chunk to one array that grows by GROWTH times
into a new one (the rows so far copied over: at most 1 / (GROWTH - 1) of them again, in all) and is cut
to its rows at the end, so the Result keeps that array. Growing in place (``ndarray.resize``) was
measured slower: numpy fills the grown part with zeros and a reallocated block gets no huge pages,
where a new large array does (about 4x the CPU of this store on the 16- and 64-link chains' steps).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import DTypeLike, NDArray

#: rows of the first array, and the factor by which a full one grows
FIRST_ROWS, GROWTH = 1024, 4


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
            grown = np.empty((max(self.n + k, GROWTH * size), *self._rows.shape[1:]), dtype=self._rows.dtype)
            grown[: self.n] = self._rows[: self.n]
            self._rows = grown
        self._rows[self.n: self.n + k] = rows
        self.n += k

    def array(self) -> NDArray:
        """The rows so far, shape ``(n, *tail)``: the store's array cut to them (its spare rows given back:
        ``resize``, which counts the array's references, so no other name may hold it here), or a view
        when an earlier one is alive."""
        if len(self._rows) > self.n:
            try:
                self._rows.resize((self.n, *self._rows.shape[1:]))
            except ValueError:
                return self._rows[: self.n]
        return self._rows
