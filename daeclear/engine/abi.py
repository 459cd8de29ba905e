"""The numbers the compiled drivers and Python share, in one table: return codes, option codes,
flags, slots of the arrays a driver fills, decision kinds (those of :mod:`daeclear.core.automaton`).

:func:`header_text` writes them as ``csrc/dc_abi.h``, generated and checked in
(``python -m daeclear.engine.abi`` writes it again, and ``csrc/dc_api.h``, the entry points of
:mod:`daeclear.engine.c_api`; ``tests/test_abi.py`` fails when one differs).

>>> DC_ROOT, FX_CANDIDATE, STAT_KEYS[DC_ST_REINITS]
(2, 2, 'n_reinits')
"""

from __future__ import annotations

from pathlib import Path
from typing import Final

from ..core import automaton
from . import c_api
from .build import CSRC

__all__ = [
    "DC_CHUNK", "DC_TSTOP", "DC_ROOT", "DC_ERR_IDA", "DC_ERR_MAXSTEPS", "DC_ERR_COLLAPSE", "DC_ERR_USAGE",
    "DC_LS_DENSE", "DC_LS_SPARSE", "DC_LS_REDUCED", "DC_LS_SUPERLU", "LINEAR_SOLVER_CODES", "DC_LU_PIVOT_TOL",
    "DC_STORE_TIMES", "DC_STORE_STATES",
    "DC_NONE", "DC_ONSET", "DC_SEPARATION", "DC_SAME_INSTANT",
    "DC_EV_KIND", "DC_EV_CONTACT", "DC_EV_HELD", "DC_EV_WATCH", "DC_EV_N",
    "DC_ST_STEPS", "DC_ST_RES", "DC_ST_JAC", "DC_ST_LSETUP", "DC_ST_NNI", "DC_ST_NCF", "DC_ST_NETF",
    "DC_ST_GEVALS", "DC_ST_REINITS", "DC_ST_LU_FALLBACKS", "DC_ST_N", "STAT_KEYS",
    "DC_BI_MAJOR", "DC_BI_MINOR", "DC_BI_PATCH", "DC_BI_INDEX_SIZE", "DC_BI_INDEX_BITS", "DC_BI_SPARSE", "DC_BI_N",
    "DCO_OK", "DCO_NONFINITE", "DCO_SINGULAR", "DCO_EVAL_ERR",
    "FX_CHUNK", "FX_TSTOP", "FX_CANDIDATE", "FX_ERR", "FX_MAXSTEPS",
    "DCO_EULER", "DCO_RK4", "DCO_CNT_RHS", "DCO_CNT_JAC", "DCO_CNT_GAPS", "DCO_CNT_STEPS", "DCO_CNT_N",
    "ODE_COUNTER_KEYS",
    "GROUPS", "table", "header_text", "HEADER", "generated_headers",
]

#: Where the generated header lives (beside the drivers that include it).
HEADER = CSRC / "dc_abi.h"

# ---------------------------------------------------------------- ida_driver.c (dc_*)
DC_CHUNK: Final = 0
DC_TSTOP: Final = 1
DC_ROOT: Final = 2
DC_ERR_IDA: Final = -1
DC_ERR_MAXSTEPS: Final = -2
DC_ERR_COLLAPSE: Final = -3
DC_ERR_USAGE: Final = -4

DC_LS_DENSE: Final = 0
DC_LS_SPARSE: Final = 1
DC_LS_REDUCED: Final = 2
DC_LS_SUPERLU: Final = 3
#: dc_open's linear_solver argument by the option's name (daeclear.core.options.LINEAR_SOLVERS but "auto")
LINEAR_SOLVER_CODES: Final = {"dense": DC_LS_DENSE, "sparse": DC_LS_SPARSE, "reduced": DC_LS_REDUCED,
                              "superlu": DC_LS_SUPERLU}
#: the sparse LU's pivot test (csrc/dc_sparse_lu.h): a pivot must keep more than this fraction of the
#: magnitude it was formed from (|u_jj| > tol (|a_jj| + sum |l_jk u_kj|)), else that Jacobian is
#: factored by dense LU with partial pivoting. Mechanisms' pivots keep 1e-5 and more of it (a KKT
#: pivot is a sum of terms of one sign); 1e-8 is half the double precision digits lost.
DC_LU_PIVOT_TOL: Final = 1e-8

DC_STORE_TIMES: Final = 1
DC_STORE_STATES: Final = 2

DC_NONE: Final = automaton.NONE
DC_ONSET: Final = automaton.ONSET
DC_SEPARATION: Final = automaton.SEPARATION
DC_SAME_INSTANT: Final = automaton.SAME_INSTANT

DC_EV_KIND: Final = 0
DC_EV_CONTACT: Final = 1
DC_EV_HELD: Final = 2
DC_EV_WATCH: Final = 3
DC_EV_N: Final = 4

#: dc_stats' slots (IDA's counters summed over the restarts, and the restarts)
DC_ST_STEPS: Final = 0
DC_ST_RES: Final = 1
DC_ST_JAC: Final = 2
DC_ST_LSETUP: Final = 3
DC_ST_NNI: Final = 4
DC_ST_NCF: Final = 5
DC_ST_NETF: Final = 6
DC_ST_GEVALS: Final = 7
DC_ST_REINITS: Final = 8
DC_ST_LU_FALLBACKS: Final = 9
DC_ST_N: Final = 10
#: (C slot name, Python key) of dc_stats, in slot order
_STATS: Final = (("DC_ST_STEPS", "n_steps"), ("DC_ST_RES", "n_res_evals"), ("DC_ST_JAC", "n_jac_evals"),
                 ("DC_ST_LSETUP", "n_lin_setups"), ("DC_ST_NNI", "n_nonlin_iters"),
                 ("DC_ST_NCF", "n_nonlin_conv_fails"), ("DC_ST_NETF", "n_err_test_fails"),
                 ("DC_ST_GEVALS", "n_root_evals"), ("DC_ST_REINITS", "n_reinits"),
                 ("DC_ST_LU_FALLBACKS", "n_lu_fallbacks"))
#: the keys of dc_stats' slots, in slot order
STAT_KEYS: Final = tuple(key for _, key in _STATS)

#: dc_build_info's slots
DC_BI_MAJOR: Final = 0
DC_BI_MINOR: Final = 1
DC_BI_PATCH: Final = 2
DC_BI_INDEX_SIZE: Final = 3
DC_BI_INDEX_BITS: Final = 4
DC_BI_SPARSE: Final = 5
DC_BI_N: Final = 6

# ---------------------------------------------------------------- ode_driver.c (dco_*)
DCO_OK: Final = 0
DCO_NONFINITE: Final = 1
DCO_SINGULAR: Final = 2
DCO_EVAL_ERR: Final = 3

FX_CHUNK: Final = 0
FX_TSTOP: Final = 1
FX_CANDIDATE: Final = 2
FX_ERR: Final = -1
FX_MAXSTEPS: Final = -2

DCO_EULER: Final = 1
DCO_RK4: Final = 4

#: dco_counters' slots
DCO_CNT_RHS: Final = 0
DCO_CNT_JAC: Final = 1
DCO_CNT_GAPS: Final = 2
DCO_CNT_STEPS: Final = 3
DCO_CNT_N: Final = 4
#: (C slot name, Python key) of dco_counters, in slot order
_ODE_COUNTERS: Final = (("DCO_CNT_RHS", "n_res_evals"), ("DCO_CNT_JAC", "n_jac_evals"),
                        ("DCO_CNT_GAPS", "n_root_evals"), ("DCO_CNT_STEPS", "n_fixed_steps"))
#: the keys of dco_counters' slots, in slot order
ODE_COUNTER_KEYS: Final = tuple(key for _, key in _ODE_COUNTERS)


def _slots(names: tuple[tuple[str, str], ...], count: str) -> tuple[tuple[str, int | float, str], ...]:
    """Slot i of each (name, comment), then the count: the values a slot table must have."""
    return tuple((name, i, doc) for i, (name, doc) in enumerate(names)) + ((count, len(names), "slots"),)


#: The table: (heading, ((C name, value, comment), ...)) per group, in the header's order.
GROUPS: Final[tuple[tuple[str, tuple[tuple[str, int | float, str], ...]], ...]] = (
    ("dc_advance return codes", (
        ("DC_CHUNK", DC_CHUNK, "a buffer is full: call again"),
        ("DC_TSTOP", DC_TSTOP, "reached t_stop"),
        ("DC_ROOT", DC_ROOT, "a root was found (not decided in C)"),
        ("DC_ERR_IDA", DC_ERR_IDA, "IDA returned an error flag"),
        ("DC_ERR_MAXSTEPS", DC_ERR_MAXSTEPS, "the session's step cap is reached"),
        ("DC_ERR_COLLAPSE", DC_ERR_COLLAPSE, "the step size collapsed"),
        ("DC_ERR_USAGE", DC_ERR_USAGE, "called in a wrong state or with bad arguments"))),
    ("linear solvers of dc_open", (
        ("DC_LS_DENSE", DC_LS_DENSE, "SUNDIALS' dense LU of the whole iteration matrix"),
        ("DC_LS_SPARSE", DC_LS_SPARSE, "sparse LU on the model's plan, dc_sparse_lu.h"),
        ("DC_LS_REDUCED", DC_LS_REDUCED, "dense LU of the reduced system, dc_reduced_ls.h"),
        ("DC_LS_SUPERLU", DC_LS_SUPERLU, "SUNDIALS' SuperLU_MT"))),
    ("the sparse LU's pivot test (dc_sparse_lu.h)", (
        ("DC_LU_PIVOT_TOL", DC_LU_PIVOT_TOL, "|u_jj| > tol (|a_jj| + sum |l_jk u_kj|), else dense LU"),)),
    ("dc_advance's store_steps flags", (
        ("DC_STORE_TIMES", DC_STORE_TIMES, "step times, sizes and orders"),
        ("DC_STORE_STATES", DC_STORE_STATES, "also the states y and yp"))),
    ("decision kinds of the contact automaton (daeclear.core.automaton)", (
        ("DC_NONE", DC_NONE, "nothing changes"),
        ("DC_ONSET", DC_ONSET, "contact starts"),
        ("DC_SEPARATION", DC_SEPARATION, "contact ends"),
        ("DC_SAME_INSTANT", DC_SAME_INSTANT, "against the rate, this near the last switch (rel. to t): round-off"))),
    ("columns of an event's info row (dc_take_events)", (
        ("DC_EV_KIND", DC_EV_KIND, "the decision's kind"),
        ("DC_EV_CONTACT", DC_EV_CONTACT, "the pair is in contact"),
        ("DC_EV_HELD", DC_EV_HELD, "the pair's term is held on (storm guard)"),
        ("DC_EV_WATCH", DC_EV_WATCH, "root direction watched next"),
        ("DC_EV_N", DC_EV_N, "columns"))),
    ("dc_stats' slots (the Python keys)", _slots(_STATS, "DC_ST_N")),
    ("dc_build_info's slots", _slots((("DC_BI_MAJOR", "SUNDIALS major version"), ("DC_BI_MINOR", "minor"),
                                      ("DC_BI_PATCH", "patch"), ("DC_BI_INDEX_SIZE", "DC_INDEX_SIZE"),
                                      ("DC_BI_INDEX_BITS", "bits of sunindextype as compiled"),
                                      ("DC_BI_SPARSE", "DC_HAVE_SPARSE")), "DC_BI_N")),
    ("return codes of dco_rhs, dco_jac, dco_gaps, dco_step", (
        ("DCO_OK", DCO_OK, "success"),
        ("DCO_NONFINITE", DCO_NONFINITE, "a value is not finite"),
        ("DCO_SINGULAR", DCO_SINGULAR, "the constraint Jacobian is singular"),
        ("DCO_EVAL_ERR", DCO_EVAL_ERR, "a generated function returned an error"))),
    ("dco_fixed return codes", (
        ("FX_CHUNK", FX_CHUNK, "step buffer full: call again"),
        ("FX_TSTOP", FX_TSTOP, "t_stop reached"),
        ("FX_CANDIDATE", FX_CANDIDATE, "the last step may hold a gap crossing"),
        ("FX_ERR", FX_ERR, "model evaluation failed or the state is not finite"),
        ("FX_MAXSTEPS", FX_MAXSTEPS, "step cap reached"))),
    ("fixed-step schemes of dco_step and dco_fixed (their order)", (
        ("DCO_EULER", DCO_EULER, "explicit Euler"),
        ("DCO_RK4", DCO_RK4, "classical Runge-Kutta"))),
    ("dco_counters' slots (the Python keys)", _slots(_ODE_COUNTERS, "DCO_CNT_N")),
)


def table() -> dict[str, int | float]:
    """Every constant of the table by its C name."""
    return {name: value for _, rows in GROUPS for name, value, _ in rows}


def _c_value(value: int | float) -> str:
    if isinstance(value, float):
        return repr(value)  # repr round-trips: the C double is this very float
    return f"({value})" if value < 0 else str(value)


def header_text() -> str:
    """The text of ``csrc/dc_abi.h``: one ``#define`` per constant of :data:`GROUPS`."""
    lines = ["/*", " * dc_abi.h -- GENERATED by daeclear/engine/abi.py (python -m daeclear.engine.abi): do not edit.",
             " * The constants the compiled drivers and Python share; Python reads them from that module.",
             " */", "#ifndef DAECLEAR_DC_ABI_H", "#define DAECLEAR_DC_ABI_H", ""]
    for heading, rows in GROUPS:
        lines.append(f"/* {heading} */")
        lines += [f"#define {name} {_c_value(value)} /* {doc} */" for name, value, doc in rows]
        lines.append("")
    lines.append("#endif")
    return "\n".join(lines) + "\n"


def generated_headers() -> dict[Path, str]:
    """Every generated header and its text: this table's ``dc_abi.h`` and the entry points' ``dc_api.h``."""
    return {HEADER: header_text(), c_api.HEADER: c_api.header_text()}


if __name__ == "__main__":  # pragma: no cover - the maintainer's regeneration step
    for path, text in generated_headers().items():
        path.write_text(text)
        print(path)
