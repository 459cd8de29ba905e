"""The entry points of the compiled drivers, declared once: the C signature of every function (and the
one datum) a built library exports.

:func:`header_text` writes them as the declarations of ``csrc/dc_api.h`` (generated and checked in,
like ``csrc/dc_abi.h``: ``python -m daeclear.engine.abi`` writes both; ``tests/test_abi.py`` fails
when one differs). Each driver includes it before its definitions, so the C compiler refuses a
definition that differs from its entry (conflicting types) and, with ``-Wmissing-prototypes`` an
error there, an exported function without one. :func:`prototypes` gives :mod:`daeclear.engine.library`
the ctypes ``restype`` and ``argtypes`` of the same entries: no prototype is written twice.

>>> IDA_ENTRY_POINTS[0].declaration
'int dc_abi_version(void)'
>>> restype, argtypes = prototypes(ODE_ENTRY_POINTS)["dco_rhs"]
>>> restype.__name__, [t.__name__ for t in argtypes]
('c_int', ['c_void_p', 'c_double', 'c_void_p', 'c_void_p'])
"""

from __future__ import annotations

import ctypes
import re
from dataclasses import dataclass
from typing import Any, Final

from .build import CSRC

__all__ = ["EntryPoint", "parse_signature", "ctype_of", "prototypes", "IDA_GROUPS", "IDA_ENTRY_POINTS", "IDA_DATA",
           "ODE_GROUPS", "ODE_ENTRY_POINTS", "header_text", "HEADER"]

#: Where the generated header lives (beside the drivers that include it).
HEADER = CSRC / "dc_api.h"

#: The C types of a value (no pointer) an entry point may take or return, as ctypes passes them.
_SCALARS: Final[dict[str, Any]] = {"int": ctypes.c_int, "long": ctypes.c_long, "long long": ctypes.c_longlong,
                                   "double": ctypes.c_double}
#: The types a pointer may point to (a ``char`` pointer is a C string for ctypes, any other an address).
_POINTEES: Final = frozenset({"void", "char", "int", "long", "long long", "double"})


@dataclass(frozen=True)
class EntryPoint:
    """One exported C function: its name, return type and (C type, name) of each parameter."""

    name: str
    restype: str
    params: tuple[tuple[str, str], ...]

    @property
    def declaration(self) -> str:
        """The C prototype (without the export attribute or the ``;``)."""
        args = ", ".join(f"{ctype} {name}" for ctype, name in self.params) or "void"
        return f"{self.restype} {self.name}({args})"


def _normal_type(text: str, where: str, result: bool = False) -> str:
    """A C type written one way (``const double* const*``), checked against the types the table allows
    (``void`` only as a ``result``)."""
    tokens = re.findall(r"\w+|\*|\S", text)
    base = " ".join(t for t in tokens if t not in ("const", "*"))
    if "*" in tokens:
        allowed = set(_POINTEES)
    else:
        allowed = {*_SCALARS, "void"} if result else set(_SCALARS)
    if base not in allowed:
        void = "void (a result), " if result else ""
        raise ValueError(f"c_api: type={text!r} of {where}, must be {void}{', '.join(_SCALARS)} or a pointer to "
                         f"one of {', '.join(sorted(_POINTEES))}.")
    out = ""
    for token in tokens:
        out += token if token == "*" or not out else " " + token
    return out


def parse_signature(signature: str) -> EntryPoint:
    """The entry point of a C prototype ``"<type> <name>(<type> <name>, ...)"`` (``(void)``: none)."""
    m = re.fullmatch(r"\s*(.+?)\s*\b(\w+)\s*\((.*)\)\s*", signature, re.S)
    if m is None:
        raise ValueError(f"c_api: signature={signature!r}, must be '<type> <name>(<type> <name>, ...)'.")
    restype, name, args = m.groups()
    params: list[tuple[str, str]] = []
    if args.strip() != "void":
        for arg in args.split(","):
            p = re.fullmatch(r"\s*(.+?)\s*\b(\w+)\s*", arg)
            if p is None:
                raise ValueError(f"c_api: parameter={arg.strip()!r} of {name}, must be '<type> <name>'.")
            params.append((_normal_type(p.group(1), f"{name}'s {p.group(2)}"), p.group(2)))
    names = [pname for _, pname in params]
    if len(set(names)) != len(names):
        raise ValueError(f"c_api: parameters={names} of {name}, must have distinct names.")
    return EntryPoint(name, _normal_type(restype, f"{name}'s result", result=True), tuple(params))


def ctype_of(ctype: str) -> Any:
    """The ctypes type of a table's C type: None for void, c_char_p for a char pointer, c_void_p for any
    other pointer (the callers pass addresses), else the scalar."""
    if ctype == "void":
        return None
    stars = ctype.count("*")
    if stars == 0:
        return _SCALARS[ctype]
    return ctypes.c_char_p if stars == 1 and ctype.removeprefix("const ").rstrip("*") == "char" else ctypes.c_void_p


def prototypes(entries: tuple[EntryPoint, ...]) -> dict[str, tuple[Any, tuple[Any, ...]]]:
    """Each entry point's (restype, argtypes) for ctypes, by name."""
    return {e.name: (ctype_of(e.restype), tuple(ctype_of(ctype) for ctype, _ in e.params)) for e in entries}


def _table(*groups: tuple[str, tuple[str, ...]]) -> tuple[tuple[str, tuple[EntryPoint, ...]], ...]:
    return tuple((heading, tuple(parse_signature(s) for s in signatures)) for heading, signatures in groups)


# ---------------------------------------------------------------- the table

#: The dc_* functions of csrc/ida_driver.c (and its ida_*.h parts), by job: (heading, entries).
IDA_GROUPS: Final = _table(
    ("the library: its build, its model", (
        "int dc_abi_version(void)",
        "int dc_build_info(int* out, int len)",
        "int dc_sundials_version(char* buf, int len)",
        "int dc_model_info(int* n, int* n_terms, int* n_roots, int* n_params)",
        "const char* dc_model_name(void)",
        "int dc_n_parameters(void)",
        "int dc_n_extra(void)",
        "int dc_sparse_plan(long long* out, int len)",
        "void dc_flag_name(long flag, char* buf, int len)",
        "int dc_eval_extra(int k, int n_points, int n_in, const double* const* inputs, const int* in_strides, "
        "double* out, int out_stride)",
        "int dc_automaton_run(int n, const double* t, const int* dir, const double* rate, int storm_events, "
        "double storm_window, double vmin, int contact0, int held0, double latched0, int* kind, int* contact, "
        "int* held, int* watch, double* latched)")),
    ("a session: open, settings, restarts", (
        "void* dc_open(double rtol, const double* atol, double max_step, int max_order, long long max_steps, "
        "const int* rootdir, const double* P, int linear_solver, char* err, int errlen)",
        "void dc_free(void* sp)",
        "const char* dc_message(void* sp)",
        "int dc_reset(void* sp, double rtol, const double* atol, double max_step, long long max_steps, "
        "const int* rootdir, const double* P)",
        "long long dc_jac_nnz(void* sp)",
        "int dc_linear_solver(void* sp)",
        "void dc_jac_pattern(void* sp, long long* colptr, long long* rowind)",
        "int dc_set_nonlin_conv_coef(void* sp, double coef)",
        "int dc_set_jacobian_refresh(void* sp, double dcj)",
        "int dc_set_stall(void* sp, double stall_step, int count)",
        "int dc_set_first_step(void* sp, int on)",
        "double dc_first_step(void* sp)",
        "int dc_set_kinematic_rows(void* sp, int nk)",
        "int dc_set_newton_atol(void* sp, const double* atol)",
        "int dc_set_layout(void* sp, int nq, int m, int ggl, int track_work, int accel_extra, int force_extra0, "
        "int kin_extra, int outputs_extra, int project, double tol, int max_iter)",
        "int dc_reinit(void* sp, double t0, const double* y0, const double* yp0, const int* active, "
        "const double* params, const int* rootdir)",
        "void dc_set_terms(void* sp, const int* active, const double* params)")),
    ("the contact pairs the loop switches itself", (
        "int dc_set_auto(void* sp, int n_auto, const int* root, const int* term, const int* rate, "
        "const int* needs, const double* vmin, const int* storm_events, const double* storm_window, "
        "const int* contact0, const int* held0, const double* latched0, int ev_cap)",
        "int dc_take_events(void* sp, int cap, double* t, int* pair, int* info, double* rate, double* latched, "
        "double* y)",
        "int dc_pending_events(void* sp)",
        "void dc_get_active(void* sp, int* active, double* params)",
        "void dc_get_pairs(void* sp, int* contact, int* held, double* free_since, double* latched, int* n_recent, "
        "double* recent)")),
    ("the loop, its statistics, the model's functions at given states", (
        "int dc_advance(void* sp, double t_stop, const double* t_eval, int n_eval, int* i_eval, double* eval_y, "
        "double* eval_yp, int store_steps, int cap, double* st, double* sy, double* syp, double* sh, int* sord, "
        "int* n_stored, double* t_out, double* y_out, double* yp_out, int* roots_out, int* flag_out)",
        "void dc_stats(void* sp, long long* out)",
        "int dc_report(void* sp, int n_points, const double* t, const double* y, const double* sw, double* y_out, "
        "double* yp_out, double* channels_out)",
        "int dc_eval_residual(void* sp, double t, const double* y, const double* yp, double* r)",
        "int dc_eval_jacobian(void* sp, double t, const double* y, const double* yp, double cj, double* J)",
        "int dc_eval_jacobian_sparse(void* sp, double t, const double* y, const double* yp, double cj, "
        "double* data)",
        "int dc_eval_roots(void* sp, double t, const double* y, const double* yp, double* g)",
        "int dc_solve_linear(void* sp, int kind, int nk, double t, const double* y, const double* yp, double cj, "
        "const double* A, double* B, int nrhs, long long* info)")),
)

#: The data csrc/ida_driver.c exports: its build tag, read from the file before it is loaded.
IDA_DATA: Final = (("const char", "dc_build_tag"),)

#: The dco_* functions of csrc/ode_driver.c, by job.
ODE_GROUPS: Final = _table(
    ("the library and a session", (
        "int dco_abi_version(void)",
        "int dco_info(int* n, int* m, int* n_terms, int* n_gaps, int* n_params)",
        "void dco_output_sizes(int* n_y, int* n_switch, int* n_channels)",
        "void* dco_open(const double* mass, const double* P, char* err, int errlen)",
        "void dco_free(void* sp)",
        "const char* dco_message(void* sp)",
        "void dco_set_terms(void* sp, const int* active, const double* params)",
        "void dco_set_hermite(void* sp, int on)",
        "void dco_counters(void* sp, long long* out)")),
    ("the model's functions and the fixed-step schemes", (
        "int dco_rhs(void* sp, double t, const double* x, double* xdot)",
        "int dco_jac(void* sp, double t, const double* x, double* J)",
        "int dco_gaps(void* sp, double t, const double* x, double* g, double* gd)",
        "int dco_batch(void* sp, int N, const double* t, const double* X, double* Xdot, double* Lam)",
        "int dco_outputs(void* sp, int N, const double* t, const double* Y, const double* YP, const double* sw, "
        "double* out)",
        "int dco_step(void* sp, int scheme, double t, const double* x, double h, double* xn)",
        "int dco_fixed(void* sp, int scheme, double t0, const double* x0, double hstep, double t_stop, "
        "long long max_steps, const int* rootdir, int cap, double* st, double* sx, int* n_stored, double* ta, "
        "double* xa, double* tb, double* xb, double* sstar)")),
)

#: Every entry point of each driver, in the header's order.
IDA_ENTRY_POINTS: Final = tuple(e for _, entries in IDA_GROUPS for e in entries)
ODE_ENTRY_POINTS: Final = tuple(e for _, entries in ODE_GROUPS for e in entries)


def _declaration_lines(entry: EntryPoint, width: int = 110) -> list[str]:
    """``DC_API <prototype>;`` broken after a comma before ``width`` columns, aligned on the ``(``."""
    head = f"DC_API {entry.restype} {entry.name}("
    parts = [f"{ctype} {name}" for ctype, name in entry.params] or ["void"]
    lines, line = [], head
    for i, part in enumerate(parts):
        piece = part + ("," if i < len(parts) - 1 else ");")
        if line == head:
            line += piece
        elif len(line) + 1 + len(piece) > width:
            lines.append(line)
            line = " " * len(head) + piece
        else:
            line += " " + piece
    return [*lines, line]


def header_text() -> str:
    """The text of ``csrc/dc_api.h``: the export attribute ``DC_API`` and one declaration per entry."""
    lines = ["/*", " * dc_api.h -- GENERATED by daeclear/engine/c_api.py (python -m daeclear.engine.abi): do not edit.",
             " * The entry points of the compiled drivers, declared once: each driver includes this before its",
             " * definitions, so the compiler checks them; Python declares them to ctypes from the same table.",
             " */", "#ifndef DAECLEAR_DC_API_H", "#define DAECLEAR_DC_API_H", "",
             "/* exported from the library, which is compiled with -fvisibility=hidden */",
             '#define DC_API __attribute__((visibility("default")))', ""]
    for driver, groups, data in (("ida_driver.c", IDA_GROUPS, IDA_DATA), ("ode_driver.c", ODE_GROUPS, ())):
        lines.append(f"/* ---------------------------------------------------------------- {driver} */")
        lines += [f"DC_API extern {ctype} {name}[];" for ctype, name in data]
        for heading, entries in groups:
            lines += ["", f"/* {heading} */"]
            lines += [line for e in entries for line in _declaration_lines(e)]
        lines.append("")
    lines.append("#endif")
    return "\n".join(lines) + "\n"
