"""The sparse LU's plan, made once per model structure when its C is generated (``csrc/dc_sparse_lu.h``
refactors numerically on it at every Jacobian, never orders or allocates again).

The Newton matrix J = dF/dy + cj dF/dy' of a mechanism has a fixed pattern: the union of the base
Jacobian's and every contact term's (a term switched off leaves explicit zeros, so the pattern never
changes with the contact state). The plan holds that union, an order of the pivots and the pattern of
the factors L + U in that order:

* **Pivots on the diagonal, in a fill-reducing order.** A greedy minimum-degree order of the
  symmetrized pattern (the elimination graph is kept exactly: a node eliminated joins its neighbours
  into a clique; ties go to the lower index, so the plan is a function of the pattern alone).
* **Multipliers after their equations' unknowns.** An unknown whose diagonal is structurally zero
  (a Lagrange multiplier lambda or mu: the KKT-like blocks of index-1 and GGL) is eliminated only
  after every unknown with a structurally nonzero diagonal that its row or column touches. Its pivot
  is then -b^T P b, b its constraint's whole row and P the (projected) inverse of the eliminated block,
  zero only when the constraints are dependent; eliminated earlier, it would be -b_k^2 / a_kk of a
  single coordinate, which passes through zero as a body turns (b_k = -l sin(phi)). Everything else
  is the iteration matrix cj M + damping + stiffness / cj after the positions, whose diagonal pivots
  are safe while its symmetric part dominates.
* **Checked at run time.** Each pivot must be at least ``DC_LU_PIVOT_TAU`` (daeclear.engine.abi) times
  the largest entry below it in its column (threshold partial pivoting's test); a factorization that
  fails it is redone by dense LU with partial pivoting for that Jacobian (counted in the statistics).

A pattern whose static pivots are structurally singular (a multiplier whose diagonal no elimination
fills) has no plan: ``SparsePlan.available`` is False and the sparse solver is refused for it.

>>> plan = make_plan(2, [0, 2, 3], [0, 1, 0])   # [[a, b], [c, 0]]: the multiplier 1 after unknown 0
>>> plan.available, plan.perm.tolist(), plan.factor_nnz   # its pivot -b c / a fills the diagonal
(True, [0, 1], 4)
>>> make_plan(2, [0, 1, 2], [0, 0]).available   # [[a, b], [0, 0]]: no elimination fills (1, 1)
False
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import casadi
import numpy as np

if TYPE_CHECKING:
    from .codegen import NormalizedModel

__all__ = ["SparsePlan", "make_plan", "union_pattern", "plan_of_model", "c_source", "NO_PLAN_C"]

#: the generated table's entry of a model without a plan
NO_PLAN_C = "0"
#: the plan's arrays in the order of csrc/dc_model.h's dc_lu_plan (after n, nnz, fnnz)
ARRAYS = ("colptr", "rowind", "perm", "fcolptr", "frow", "fdiag", "lrowptr", "lrowcol", "lrowpos")


@dataclass(frozen=True)
class SparsePlan:
    """The union pattern (CSC, rows ascending: ``colptr``, ``rowind``), the pivot order (pivot k is
    unknown ``perm[k]``) and the factors' pattern in that order (CSC ``fcolptr``, ``frow``, rows
    ascending; ``fdiag[j]`` the diagonal's position in column j: U above it, L below) and L by rows
    (``lrowptr``; ``lrowcol`` the column k and ``lrowpos`` the position of each L(j, k)): the pivot
    test's terms. ``available`` is False when the static pivots are structurally singular (``reason``
    says which unknown)."""

    n: int
    colptr: np.ndarray
    rowind: np.ndarray
    perm: np.ndarray
    fcolptr: np.ndarray
    frow: np.ndarray
    fdiag: np.ndarray
    lrowptr: np.ndarray
    lrowcol: np.ndarray
    lrowpos: np.ndarray
    available: bool = True
    reason: str = ""

    @property
    def nnz(self) -> int:
        """Nonzeros of the union pattern."""
        return int(self.colptr[-1])

    @property
    def factor_nnz(self) -> int:
        """Nonzeros of L + U (the diagonal counted once)."""
        return int(self.fcolptr[-1])


def union_pattern(n: int, patterns: Iterable[casadi.Sparsity]) -> tuple[np.ndarray, np.ndarray]:
    """The union of n x n CasADi patterns as CSC arrays (colptr, rowind), rows ascending in each column:
    the pattern ``build_jac_pattern`` of ida_eval.h builds in C from the same functions."""
    cols: list[set[int]] = [set() for _ in range(n)]
    for sp in patterns:
        if (sp.size1(), sp.size2()) != (n, n):
            raise ValueError(f"union_pattern: a {sp.size1()} x {sp.size2()} pattern, must be {n} x {n}")
        colind, row = sp.colind(), sp.row()
        for c in range(n):
            cols[c].update(row[colind[c]:colind[c + 1]])
    colptr = np.zeros(n + 1, dtype=np.int64)
    rowind: list[int] = []
    for c in range(n):
        rowind += sorted(cols[c])
        colptr[c + 1] = len(rowind)
    return colptr, np.asarray(rowind, dtype=np.int64)


def _structure(n: int, colptr: np.ndarray, rowind: np.ndarray) -> tuple[list[set[int]], np.ndarray]:
    """The symmetrized neighbours of each unknown (diagonal left out) and which diagonals are present."""
    adj: list[set[int]] = [set() for _ in range(n)]
    diag = np.zeros(n, dtype=bool)
    for c in range(n):
        for r in rowind[colptr[c]:colptr[c + 1]].tolist():
            if r == c:
                diag[c] = True
            else:
                adj[c].add(r)
                adj[r].add(c)
    return adj, diag


def pivot_order(n: int, colptr: np.ndarray, rowind: np.ndarray) -> np.ndarray:
    """The minimum-degree order with multipliers after their neighbours (see the module docstring)."""
    adj, diag = _structure(n, colptr, rowind)
    original = [set(a) for a in adj]
    guards = [0 if diag[i] else sum(1 for j in original[i] if diag[j]) for i in range(n)]
    done = np.zeros(n, dtype=bool)
    heap = [(len(adj[i]), i) for i in range(n) if guards[i] == 0]
    heapq.heapify(heap)
    order: list[int] = []
    while heap:
        deg, i = heapq.heappop(heap)
        if done[i] or deg != len(adj[i]):
            continue  # eliminated already, or a stale degree (its current one is in the heap too)
        done[i] = True
        order.append(i)
        nbrs = adj[i]
        for u in nbrs:  # the neighbours become a clique; i leaves the graph
            adj[u].discard(i)
            adj[u].update(w for w in nbrs if w != u)
            if guards[u] == 0:
                heapq.heappush(heap, (len(adj[u]), u))
        if diag[i]:
            for z in original[i]:
                if not diag[z]:
                    guards[z] -= 1
                    if guards[z] == 0:
                        heapq.heappush(heap, (len(adj[z]), z))
        adj[i] = set()
    if len(order) != n:  # cannot happen: every unknown is eligible once the diagonal ones are gone
        raise AssertionError("pivot_order: unknowns left over")
    return np.asarray(order, dtype=np.int64)


def symbolic_lu(n: int, colptr: np.ndarray, rowind: np.ndarray, perm: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The pattern of L + U of the symmetrically permuted matrix B = J[perm][:, perm] with the pivots on
    its diagonal (exact unsymmetric fill): (fcolptr, frow, fdiag, first pivot that is structurally zero or -1)."""
    pinv = np.empty(n, dtype=np.int64)
    pinv[perm] = np.arange(n)
    below: list[set[int]] = [set() for _ in range(n)]  # column j of L: rows > j
    right: list[set[int]] = [set() for _ in range(n)]  # row i of U: columns > i
    diag = np.zeros(n, dtype=bool)
    for c in range(n):
        j = int(pinv[c])
        for r in rowind[colptr[c]:colptr[c + 1]].tolist():
            i = int(pinv[r])
            if i > j:
                below[j].add(i)
            elif i < j:
                right[i].add(j)
            else:
                diag[i] = True
    singular = -1
    for k in range(n):
        if not diag[k] and singular < 0:
            singular = k
        rows, cols = below[k], right[k]
        if not rows or not cols:
            continue
        for i in rows:  # fill: (i, j) for every row i below and column j right of the pivot
            right[i].update(j for j in cols if j > i)
            if i in cols:
                diag[i] = True
        for j in cols:
            below[j].update(i for i in rows if i > j)
    upper: list[list[int]] = [[] for _ in range(n)]
    for i in range(n):
        for j in right[i]:
            upper[j].append(i)
    fcolptr = np.zeros(n + 1, dtype=np.int64)
    fdiag = np.zeros(n, dtype=np.int64)
    frow: list[int] = []
    for j in range(n):
        frow += sorted(upper[j])
        fdiag[j] = len(frow)
        frow.append(j)
        frow += sorted(below[j])
        fcolptr[j + 1] = len(frow)
    return fcolptr, np.asarray(frow, dtype=np.int64), fdiag, singular


def l_rows(n: int, fcolptr: np.ndarray, frow: np.ndarray, fdiag: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """L's entries by rows: (lrowptr, lrowcol, lrowpos), the columns of each row in increasing order."""
    rows: list[list[tuple[int, int]]] = [[] for _ in range(n)]
    for k in range(n):
        for pos in range(int(fdiag[k]) + 1, int(fcolptr[k + 1])):
            rows[int(frow[pos])].append((k, pos))
    lrowptr = np.zeros(n + 1, dtype=np.int64)
    lrowptr[1:] = np.cumsum([len(r) for r in rows])
    flat = [pair for r in rows for pair in r]
    return (lrowptr, np.asarray([k for k, _ in flat], dtype=np.int64), np.asarray([p for _, p in flat], dtype=np.int64))


def make_plan(n: int, colptr: Sequence[int] | np.ndarray, rowind: Sequence[int] | np.ndarray) -> SparsePlan:
    """The plan of an n x n pattern given as CSC arrays (rows ascending in each column)."""
    cp, ri = np.asarray(colptr, dtype=np.int64), np.asarray(rowind, dtype=np.int64)
    if cp.shape != (n + 1,) or cp[0] != 0 or np.any(np.diff(cp) < 0) or ri.shape != (int(cp[-1]),) \
            or (ri.size and (ri.min() < 0 or ri.max() >= n)):
        raise ValueError(f"make_plan: colptr/rowind are not an {n} x {n} CSC pattern")
    perm = pivot_order(n, cp, ri)
    fcolptr, frow, fdiag, singular = symbolic_lu(n, cp, ri, perm)
    lrowptr, lrowcol, lrowpos = l_rows(n, fcolptr, frow, fdiag)
    reason = "" if singular < 0 else (
        f"unknown {int(perm[singular])}'s diagonal stays structurally zero whatever is eliminated before it")
    return SparsePlan(n, cp, ri, perm, fcolptr, frow, fdiag, lrowptr, lrowcol, lrowpos, singular < 0, reason)


def plan_of_model(model: NormalizedModel) -> SparsePlan:
    """The plan of a model's Newton matrix (its base and term Jacobians)."""
    colptr, rowind = union_pattern(model.n_jac, [f.sparsity_out(0) for f in (model.jac, *model.term_jac)])
    return make_plan(model.n_jac, colptr, rowind)


def _c_array(name: str, values: np.ndarray) -> str:
    body = ",".join(str(int(v)) for v in values.tolist()) if values.size else "0"
    return f"static const int {name}[{max(int(values.size), 1)}] = {{{body}}};"


def c_source(plan: SparsePlan) -> tuple[list[str], str]:
    """The plan as C: static arrays and the ``dc_lu_plan`` they make (csrc/dc_model.h), and the expression
    the model table refers to it by (``NO_PLAN_C`` when it has none)."""
    if not plan.available:
        return [f"/* no sparse LU plan: {plan.reason} */"], NO_PLAN_C
    lines = [_c_array(f"dc_lu_{name}", getattr(plan, name))
             for name in ARRAYS]
    lines.append(f"static const dc_lu_plan dc_lu_plan_tab = {{{plan.n}, {plan.nnz}, {plan.factor_nnz}, "
                 + ", ".join(f"dc_lu_{name}" for name in ARRAYS) + "};")
    return lines, "&dc_lu_plan_tab"
