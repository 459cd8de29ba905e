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


def test_the_array_is_cut_to_its_rows_and_one_handed_out_stays_valid():
    store = RowStore((2,))
    for i in range(5 * FIRST_ROWS // 100):
        store.append(np.full((100, 2), float(i)))
    a = store.array()
    assert a.shape == (store.n, 2) and a.base is None  # its own array, the spare rows given back
    assert np.array_equal(a[::100, 0], np.arange(5 * FIRST_ROWS // 100))
    store.append(np.broadcast_to(np.array([7.0, 8.0]), (3, 2)))  # a broadcast row, written 3 times
    b = store.array()
    assert np.array_equal(a, b[: len(a)]) and np.array_equal(b[len(a):], [[7.0, 8.0]] * 3)
    assert a.shape == (store.n - 3, 2) and a[-1, 0] == 5 * FIRST_ROWS // 100 - 1  # untouched
    c = store.array()  # b is alive: a view of the same rows
    assert c.shape == b.shape and np.shares_memory(b, c)


def test_zero_width_rows():
    store = RowStore((0,))
    store.append(np.empty((4, 0)))
    store.append(np.empty((3 * FIRST_ROWS, 0)))
    assert store.array().shape == (4 + 3 * FIRST_ROWS, 0)
