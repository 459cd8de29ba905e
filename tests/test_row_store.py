"""RowStore: a run's points appended chunk by chunk and stored once (solvers/row_store.py)."""

import numpy as np

from daeclear.solvers.row_store import FIRST_ROWS, RowStore


def test_rows_are_the_chunks_joined_in_order():
    rng = np.random.default_rng(1)
    chunks = [rng.random((k, 5)) for k in (3, FIRST_ROWS, 1, 2 * FIRST_ROWS + 7, 0, 40)]
    store = RowStore((5,))
    for c in chunks:
        store.append(c)
    assert np.array_equal(store.array(), np.concatenate(chunks))
    times = RowStore(())
    for c in chunks:
        times.append(c[:, 0])
    assert np.array_equal(times.array(), np.concatenate([c[:, 0] for c in chunks]))


def test_growth_is_in_place_and_an_array_handed_out_stays_valid():
    store = RowStore((2,))
    first = id(store.array())  # the store's own array (no reference kept: resize counts them)
    for i in range(5 * FIRST_ROWS // 100):
        store.append(np.full((100, 2), float(i)))
        assert id(store.array()) == first  # grown without a new array (realloc), each row copied once
    a = store.array()
    assert id(a) == first and len(a) == store.n  # cut to its rows
    store.append(np.broadcast_to(np.array([7.0, 8.0]), (3, 2)))  # a broadcast row, written 3 times
    b = store.array()
    assert np.array_equal(a, b[: len(a)]) and np.array_equal(b[len(a):], [[7.0, 8.0]] * 3)
    assert a[-1, 0] == 5 * FIRST_ROWS // 100 - 1  # the array handed out earlier is untouched


def test_zero_width_rows():
    store = RowStore((0,))
    store.append(np.empty((4, 0)))
    store.append(np.empty((3 * FIRST_ROWS, 0)))
    assert store.array().shape == (4 + 3 * FIRST_ROWS, 0)
