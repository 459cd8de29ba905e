"""C code generation of a DAE model (and of an ODE model) from its CasADi functions.

``build_model_library(funcs)`` turns a :class:`daeclear.engine.session_base.DAEFunctions` into a shared
library that holds

* the model's CasADi functions generated as C by ``casadi.CodeGenerator`` (symbols ``dc_res``,
  ``dc_jac``, ``dc_roots``, ``dc_term<k>_res``, ``dc_term<k>_jac``, ``dc_extra<k>``), every one
  normalised to dense column-vector inputs; the residual and the roots have dense outputs, the
  Jacobians, the terms' residuals and the extras keep their sparsity (the driver scatters their
  nonzeros, see :class:`NormalizedModel`);
* a small generated table (``dc_model``: sizes, parameter counts, function pointers; layout in
  ``csrc/dc_model.h``);
* the hand-written driver ``csrc/ida_driver.c`` (IDA loop, callbacks, dense output);

linked against the SUNDIALS libraries shipped inside the scikit-sundae wheel
(``<site-packages>/scikit_sundae.libs``) by full path, with that directory as rpath (and ``-z defs``:
a function the libraries lack fails the link). The driver is compiled against the vendored SUNDIALS
headers (:mod:`daeclear.engine.sundials`): the wheel's SUNDIALS version and ``sunindextype`` width
must equal the vendored headers' (checked before compiling) and are handed to the compiler
(``-DDC_SUNDIALS_MAJOR=7 ... -DDC_INDEX_SIZE=32``), where ``sundials_config.h`` checks them again
with ``#error``. The sparse matrix and SuperLU_MT libraries are linked too when the wheel has them
(``-DDC_HAVE_SPARSE=1``: the sparse linear solver of the driver). ``build_ode_library`` does the
same for an :class:`OdeSpec` with ``csrc/ode_driver.c`` and no SUNDIALS.

Compiling and caching is :mod:`daeclear.engine.build` (the key also holds every vendored SUNDIALS
header, the SUNDIALS version and index size, and the SUNDIALS library paths), loading is
:mod:`daeclear.engine.library`. The names of both that were defined here before are still
importable from this module.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi

from . import sundials
from ..errors import AssemblyError
from .build import (
    CSRC,
    BuildResult,
    CompileError,
    CompilerUnavailable,
    MemoTable,
    cache_dir,
    clear_memos,
    compile_cached,
    compiler_command,
    driver_files,
    memo_table,
)
from .library import DRIVER_ABI, ODE_DRIVER_ABI
from .stall_guard import c_defines
from .sundials import (
    SPARSE_LIBS,
    SUNDIALS_INCLUDE,
    SUNDIALS_LIBS,
    SUNDIALS_MAJOR,
    SundialsInfo,
    SundialsMismatch,
    check_vendored,
    parse_index_size,
    read_build_tag,
    sundials_info,
    sundials_libraries,
    vendored_sundials,
)

__all__ = [
    "CompilerUnavailable",
    "CompileError",
    "NormalizedModel",
    "BuildResult",
    "normalize_model",
    "generate_source",
    "compiler_command",
    "sundials_libraries",
    "SundialsInfo",
    "SundialsMismatch",
    "sundials_info",
    "parse_index_size",
    "vendored_sundials",
    "check_vendored",
    "SUNDIALS_INCLUDE",
    "read_build_tag",
    "cache_dir",
    "build_model_library",
    "clear_memos",
    # also re-exported from their new homes (build, sundials, library)
    "CSRC",
    "SUNDIALS_LIBS",
    "SPARSE_LIBS",
    "SUNDIALS_MAJOR",
    "DRIVER_ABI",
    "ODE_DRIVER_ABI",
    "MemoTable",
    "memo_table",
    "compile_cached",
]

#: The IDA driver and the csrc/ files it includes (its parts, dc_abi.h, the shared headers).
DRIVER_SOURCES = tuple(p.name for p in driver_files("ida_driver.c"))
CFLAGS = (f"-DDC_ABI_VERSION={DRIVER_ABI}", "-O2", "-fPIC", "-shared", "-fvisibility=hidden",
          "-Werror=incompatible-pointer-types", "-Werror=implicit-function-declaration", "-Wl,-z,defs")


# --------------------------------------------------------------------------- normalisation


@dataclass(frozen=True)
class NormalizedModel:
    """The model's functions with column-vector inputs, the run-time parameters ``P`` last.

    Signatures (sizes): ``res (1, n, n, n_P) -> n``; ``jac (1, n, n, 1, n_P) -> n x n``;
    ``term_res[k] (1, n, n, p_k, n_P) -> n``; ``term_jac[k] (1, n, n, p_k, 1, n_P) -> n x n``;
    ``roots (1, n, n, n_P) -> n_roots`` or None; ``extras[k] (..., n_P) -> vector``. The
    residual and the roots have dense outputs; the Jacobians, the terms' residuals and the extras
    keep CasADi's sparsity (compressed column storage: the driver adds a term's nonzeros to the
    residual and scatters an extra's into a dense vector, ``extra_dense``; the Python backend
    takes :meth:`dense` copies), so generated code grows with their nonzeros, not with n^2 (a
    term touches two bodies of a chain of N).
    """

    n: int
    name: str
    res: casadi.Function
    jac: casadi.Function
    term_res: tuple[casadi.Function, ...]
    term_jac: tuple[casadi.Function, ...]
    roots: casadi.Function | None
    n_params: tuple[int, ...]
    n_roots: int
    extras: tuple[casadi.Function, ...] = ()
    n_parameters: int = 0

    def dense(self, f: casadi.Function) -> casadi.Function:
        """``f`` with a dense output (for the Python backend, which adds whole matrices)."""
        return densified(f)


def densified(f: casadi.Function) -> casadi.Function:
    """``f`` with dense outputs: for the Python evaluators, which read whole vectors and matrices
    through FunctionBuffer (the generated C keeps the sparsity and its drivers scatter)."""
    ins = [casadi.MX.sym(f"i{k}", f.sparsity_in(k)) for k in range(f.n_in())]
    return casadi.Function(f.name() + "_dense", ins, [casadi.densify(o) for o in f.call(ins)])


def _check(f: Any, what: str, sizes: list[int | None], out_numel: int | None) -> list[int]:
    if not isinstance(f, casadi.Function):
        raise AssemblyError(f"{what} must be a casadi.Function, got {type(f).__name__}")
    if f.n_in() != len(sizes):
        raise AssemblyError(f"{what} ({f.name()}) must take {len(sizes)} inputs, it takes {f.n_in()}")
    if f.n_out() < 1:
        raise AssemblyError(f"{what} ({f.name()}) has no output")
    got = []
    for i, want in enumerate(sizes):
        sz = f.size_in(i)
        if min(sz) > 1 and want != 0:
            raise AssemblyError(f"{what} ({f.name()}) input {i} must be a vector, it is {sz[0]}x{sz[1]}")
        numel = f.numel_in(i)
        if want is not None and numel != want:
            raise AssemblyError(f"{what} ({f.name()}) input {i} must have {want} elements, it has {numel}")
        got.append(numel)
    if out_numel is not None and f.numel_out(0) != out_numel:
        raise AssemblyError(
            f"{what} ({f.name()}) output must have {out_numel} elements, it has {f.numel_out(0)}"
        )
    return got


def _with_parameters(f: Any, n_base: int, n_parameters: int) -> Any:
    """``f`` with the run-time parameter input last: as it is when it has one, else with an
    unused input of ``n_parameters`` elements (hand-made models without parameters)."""
    if not isinstance(f, casadi.Function) or f.n_in() != n_base:
        return f
    sym = casadi.SX if f.is_a("SXFunction") else casadi.MX
    # list[Any]: all SX or all MX at run time; casadi's stubs take no list of SX | MX
    ins: list[Any] = [sym.sym(f"i{k}", f.sparsity_in(k)) for k in range(n_base)] + [sym.sym("P", n_parameters)]
    return casadi.Function(f.name(), ins, f.call(ins[:n_base]))


def _wrap(f: casadi.Function, name: str, in_sizes: list[int], out_shape: tuple[int, int],
          keep_sparsity: bool = False) -> casadi.Function:
    """Same function with column-vector inputs and an output of out_shape (dense unless
    ``keep_sparsity``)."""
    sym = casadi.SX if f.is_a("SXFunction") else casadi.MX
    # list[Any]: all SX or all MX at run time; casadi's stubs take no list of SX | MX
    ins: list[Any] = [sym.sym(f"i{k}", s) for k, s in enumerate(in_sizes)]
    args: list[Any] = [casadi.reshape(x, f.size_in(k)) for k, x in enumerate(ins)]
    out = casadi.reshape(f.call(args)[0], out_shape[0], out_shape[1])
    return casadi.Function(name, ins, [out if keep_sparsity else casadi.densify(out)])


def normalize_model(funcs: Any) -> NormalizedModel:
    """Validate a DAEFunctions and return its uniformly named functions (parameters last)."""
    n = int(funcs.n)
    if n < 1:
        raise AssemblyError(f"DAEFunctions.n must be >= 1, got {n}")
    n_P = int(getattr(funcs, "n_parameters", 0))
    residual = _with_parameters(funcs.residual, 3, n_P)
    jacobian = _with_parameters(funcs.jacobian, 4, n_P)
    _check(residual, "residual", [1, n, n, n_P], n)
    _check(jacobian, "jacobian", [1, n, n, 1, n_P], n * n)
    if len(funcs.term_residuals) != len(funcs.term_jacobians):
        raise AssemblyError(
            f"{len(funcs.term_residuals)} term residuals but {len(funcs.term_jacobians)} term Jacobians"
        )
    res = _wrap(residual, "dc_res", [1, n, n, n_P], (n, 1))
    jac = _wrap(jacobian, "dc_jac", [1, n, n, 1, n_P], (n, n), keep_sparsity=True)
    tres, tjac, n_params = [], [], []
    for k, (fr, fj) in enumerate(zip(funcs.term_residuals, funcs.term_jacobians)):
        fr, fj = _with_parameters(fr, 4, n_P), _with_parameters(fj, 5, n_P)
        p = _check(fr, f"term_residuals[{k}]", [1, n, n, None, n_P], n)[3]
        _check(fj, f"term_jacobians[{k}]", [1, n, n, p, 1, n_P], n * n)
        tres.append(_wrap(fr, f"dc_term{k}_res", [1, n, n, p, n_P], (n, 1), keep_sparsity=True))
        tjac.append(_wrap(fj, f"dc_term{k}_jac", [1, n, n, p, 1, n_P], (n, n), keep_sparsity=True))
        n_params.append(p)
    roots = None
    n_roots = 0
    if funcs.roots is not None:
        froots = _with_parameters(funcs.roots, 3, n_P)
        _check(froots, "roots", [1, n, n, n_P], None)
        n_roots = int(froots.numel_out(0))
        if n_roots > 0:
            roots = _wrap(froots, "dc_roots", [1, n, n, n_P], (n_roots, 1))
    extras = []
    for k, f in enumerate(getattr(funcs, "extras", ())):
        if n_P == 0 and (f.n_in() == 0 or f.numel_in(f.n_in() - 1) != 0):
            f = _with_parameters(f, f.n_in(), 0)
        sizes = _check(f, f"extras[{k}]", [None] * f.n_in(), None)
        if sizes[-1] != n_P:
            raise AssemblyError(f"extras[{k}] ({f.name()}) must take the {n_P} run-time parameters as its last input")
        extras.append(_wrap(f, f"dc_extra{k}", sizes, (f.numel_out(0), 1), keep_sparsity=True))
    return NormalizedModel(
        extras=tuple(extras),
        n=n,
        name=str(getattr(funcs, "name", "model")),
        res=res,
        jac=jac,
        term_res=tuple(tres),
        term_jac=tuple(tjac),
        roots=roots,
        n_params=tuple(n_params),
        n_roots=n_roots,
        n_parameters=n_P,
    )


# --------------------------------------------------------------------------- C source


def _c_string(s: str) -> str:
    return '"' + "".join(c if c.isalnum() or c in " _-.:/" else "_" for c in s)[:200] + '"'


def _fun_entry(name: str) -> str:
    return (
        f"{{{name}, {name}_work, {name}_checkout, {name}_release, {name}_incref, {name}_decref, "
        f'{name}_sparsity_out, "{name}"}}'
    )


_NO_FUN = "{0, 0, 0, 0, 0, 0, 0, 0}"


def generate_source(model: NormalizedModel) -> str:
    """CasADi-generated C for every function of the model, plus the dc_model table."""
    cg = casadi.CodeGenerator(
        "dc_model_gen.c",
        {"with_header": False, "casadi_int": "long long int", "casadi_real": "double"},
    )
    funs = [model.res, model.jac, *model.term_res, *model.term_jac, *model.extras]
    if model.roots is not None:
        funs.append(model.roots)
    for f in funs:
        cg.add(f)
    src = cg.dump()
    nt = len(model.term_res)
    lines = [
        "",
        "/* ---------------------------------------------------------------- daeclear table */",
        '#include "dc_model.h"',
    ]
    if nt:
        lines.append(f"static const int dc_n_params_tab[{nt}] = {{{', '.join(map(str, model.n_params))}}};")
        lines.append(f"static const dc_fun_t dc_term_res_tab[{nt}] = {{")
        lines += [f"  {_fun_entry(f'dc_term{k}_res')}," for k in range(nt)]
        lines.append("};")
        lines.append(f"static const dc_fun_t dc_term_jac_tab[{nt}] = {{")
        lines += [f"  {_fun_entry(f'dc_term{k}_jac')}," for k in range(nt)]
        lines.append("};")
    roots_entry = _fun_entry("dc_roots") if model.roots is not None else _NO_FUN
    ne = len(model.extras)
    lines.append(f"const int dc_n_extras = {ne};")
    lines.append(f"const dc_fun_t dc_extra_tab[{max(ne, 1)}] = {{")
    lines += [f"  {_fun_entry(f'dc_extra{k}')}," for k in range(ne)] or [f"  {_NO_FUN},"]
    lines.append("};")
    lines += [
        "const dc_model_t dc_model = {",
        f"  {model.n}, {nt}, {model.n_roots}, {model.n_parameters},",
        f"  {'dc_n_params_tab' if nt else '0'},",
        f"  {_fun_entry('dc_res')},",
        f"  {_fun_entry('dc_jac')},",
        f"  {roots_entry},",
        f"  {'dc_term_res_tab' if nt else '0'},",
        f"  {'dc_term_jac_tab' if nt else '0'},",
        f"  {_c_string(model.name)}",
        "};",
        "",
    ]
    return src + "\n".join(lines)


# --------------------------------------------------------------------------- build


def _driver_text() -> str:
    """The driver sources and every vendored SUNDIALS file, as a SHA-256 for the cache key:
    editing any of them builds again. Files are read again only when one's size or mtime moved."""
    files = [CSRC / name for name in DRIVER_SOURCES]
    files += sorted(p for p in sundials.SUNDIALS_INCLUDE.parent.rglob("*") if p.is_file())
    stats = [(p, p.stat()) for p in files]
    return _files_digest(tuple((str(p), st.st_mtime_ns, st.st_size) for p, st in stats))


@functools.lru_cache(maxsize=8)
def _files_digest(stamps: tuple[tuple[str, int, int], ...]) -> str:
    h = hashlib.sha256()
    for name, _, _ in stamps:
        path = Path(name)
        h.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
    return "driver sources sha256 " + h.hexdigest()


def build_model_library(funcs: Any, *, model: NormalizedModel | None = None) -> BuildResult:
    """Generate, compile (or find in the cache) the shared library for a DAEFunctions (kept in
    ``funcs.compiled``: a model of the same structure run again skips code generation, tens of ms)."""
    known = funcs.compiled.get("built")
    if known is not None and known.path.exists():
        return dataclasses.replace(known, cache_hit=True, compile_time=0.0, codegen_time=0.0)
    result = _build_model_library(funcs, model=model)
    funcs.compiled["built"] = result
    return result


def _build_model_library(funcs: Any, *, model: NormalizedModel | None = None) -> BuildResult:
    t0 = time.perf_counter()
    if model is None:
        model = normalize_model(funcs)
    # through the module: tests fake the wheel's SUNDIALS there
    libdir, libs = sundials.sundials_libraries()
    info = sundials.sundials_info()
    sundials.check_vendored(info)
    names = SUNDIALS_LIBS + (SPARSE_LIBS if info.has_sparse else ())
    source = generate_source(model)
    link = [str(libs[name]) for name in names] + [f"-Wl,-rpath,{libdir}", "-lm"]
    flags = [*CFLAGS, *c_defines(), f"-I{sundials.SUNDIALS_INCLUDE}", *info.compile_flags()]
    gomp = sorted(libdir.glob("libgomp-*.so*")) if info.has_sparse else []
    if gomp:  # SuperLU_MT's OpenMP runtime: the driver keeps its teams at one thread
        link.insert(len(names), str(gomp[0]))
        flags.append("-DDC_SUPERLUMT_OMP=1")
    # the -D flags are hashed with the command; version and index size are named in the key too
    key = [f"SUNDIALS {info.version} sunindextype {info.index_size}-bit sparse {int(info.has_sparse)}",
           "\n".join(str(libs[name]) for name in names)]
    return compile_cached("dc", f"the model {model.name!r}", source, "ida_driver.c", _driver_text(), flags, link,
                          key, t0)


# --------------------------------------------------------------------------- ODE libraries
# (for the explicit and scipy integrators of daeclear.solvers.explicit; no SUNDIALS involved)

#: The ODE driver and the csrc/ files it includes.
ODE_DRIVER_SOURCES = tuple(p.name for p in driver_files("ode_driver.c"))
__all__ += ["OdeSpec", "generate_ode_source", "build_ode_library"]


@dataclass(frozen=True)
class OdeSpec:
    """An index-1 mechanism as an ODE in x = (q, v), as CasADi functions for ``csrc/ode_driver.c``.

    Sizes: n coordinates, m constraints. Every function has dense column-vector inputs; its
    outputs keep their sparsity (the driver scatters them into dense arrays, matrices column-major):

    * ``sys``: (t[1], q[n], v[n]) -> (Q[n], Phi_q[m x n], c[m]), c the Baumgarte right-hand side;
    * ``sys_jac``: (t, q, v, a[n], lam[m]) -> d[Phi_q^T lam - Q; Phi_q a - c]/d(q, v), (n+m) x 2n;
    * ``gaps``: (t, q, v) -> (g[n_gaps], dg/dt[n_gaps]) or None;
    * ``term_force[k]``: (t, q, v, p_k) -> F_k[n]; ``term_jac[k]``: same inputs -> dF_k/d(q, v), n x 2n;
    * ``outputs`` (optional): (t, y, yp, switch) -> channel values, evaluated point by point by
      ``dco_outputs`` (the model's output channels without a CasADi map over many points).

    Every function also takes the ``n_parameters`` run-time parameters P as its last input;
    ``mass`` and ``parameters`` are data given to the compiled library when it is opened, so
    the generated source depends on the structure only.
    """

    n: int
    m: int
    mass: tuple[float, ...]
    sys: casadi.Function
    sys_jac: casadi.Function
    gaps: casadi.Function | None
    term_force: tuple[casadi.Function, ...]
    term_jac: tuple[casadi.Function, ...]
    n_params: tuple[int, ...]
    name: str = "model"
    outputs: casadi.Function | None = None
    n_parameters: int = 0
    parameters: tuple[float, ...] = ()

    @property
    def n_gaps(self) -> int:
        return 0 if self.gaps is None else int(self.gaps.numel_out(0))


def _check_ode_spec(spec: OdeSpec) -> None:
    n, m = spec.n, spec.m

    def check(f: Any, what: str, ins: list[int], outs: list[int]) -> None:
        if not isinstance(f, casadi.Function):
            raise AssemblyError(f"OdeSpec.{what} must be a casadi.Function, got {type(f).__name__}")
        got_in = [f.numel_in(i) for i in range(f.n_in())]
        got_out = [f.numel_out(i) for i in range(f.n_out())]
        if got_in != ins or got_out != outs:
            raise AssemblyError(f"OdeSpec.{what} ({f.name()}): input sizes {got_in} and output sizes "
                                f"{got_out}, expected {ins} and {outs}")

    if len(spec.mass) != n or not all(mk > 0 for mk in spec.mass):
        raise AssemblyError(f"OdeSpec.mass must hold {n} positive values, got {list(spec.mass)}")
    n_P = spec.n_parameters
    if len(spec.parameters) != n_P:
        raise AssemblyError(f"OdeSpec.parameters must hold {n_P} values, got {len(spec.parameters)}")
    check(spec.sys, "sys", [1, n, n, n_P], [n, m * n, m])
    check(spec.sys_jac, "sys_jac", [1, n, n, n, m, n_P], [(n + m) * 2 * n])
    if spec.gaps is not None:
        check(spec.gaps, "gaps", [1, n, n, n_P], [spec.n_gaps, spec.n_gaps])
    if not (len(spec.term_force) == len(spec.term_jac) == len(spec.n_params)):
        raise AssemblyError("OdeSpec: term_force, term_jac and n_params must have the same length")
    for k, (ff, fj, p) in enumerate(zip(spec.term_force, spec.term_jac, spec.n_params)):
        check(ff, f"term_force[{k}]", [1, n, n, p, n_P], [n])
        check(fj, f"term_jac[{k}]", [1, n, n, p, n_P], [n * 2 * n])
    if spec.outputs is not None:
        f = spec.outputs
        if not isinstance(f, casadi.Function) or f.n_in() != 5 or f.n_out() != 1 or f.numel_in(0) != 1 \
                or f.numel_in(1) != f.numel_in(2) or f.numel_in(4) != n_P:
            raise AssemblyError("OdeSpec.outputs must be a casadi.Function (t[1], y[n_y], yp[n_y], switch, P) "
                                "-> channels")


def generate_ode_source(spec: OdeSpec) -> str:
    """CasADi-generated C for every function of an OdeSpec, plus the dco_model table."""
    _check_ode_spec(spec)
    cg = casadi.CodeGenerator(
        "dco_model_gen.c",
        {"with_header": False, "casadi_int": "long long int", "casadi_real": "double"},
    )
    nt = len(spec.term_force)
    funs = {"dcog_sys": spec.sys, "dcog_sys_jac": spec.sys_jac}
    if spec.gaps is not None:
        funs["dcog_gaps"] = spec.gaps
    for k in range(nt):
        funs[f"dcog_term{k}_force"] = spec.term_force[k]
        funs[f"dcog_term{k}_jac"] = spec.term_jac[k]
    if spec.outputs is not None:
        funs["dcog_outputs"] = spec.outputs
    for name, f in funs.items():
        # re-wrap under the C symbol name the table refers to
        # list[Any]: all SX or all MX at run time; casadi's stubs take no list of SX | MX
        ins: list[Any] = [casadi.SX.sym(f"i{i}", f.numel_in(i)) if f.is_a("SXFunction") else
                          casadi.MX.sym(f"i{i}", f.numel_in(i)) for i in range(f.n_in())]
        args: list[Any] = [casadi.reshape(x, f.size_in(i)) for i, x in enumerate(ins)]
        cg.add(casadi.Function(name, ins, f.call(args)))  # sparsity kept: ode_driver.c's call() scatters
    src = cg.dump()
    lines = [
        "",
        "/* ---------------------------------------------------------------- daeclear ODE table */",
        '#include "dco_model.h"',
    ]
    if nt:
        lines.append(f"static const int dco_n_params_tab[{nt}] = {{{', '.join(map(str, spec.n_params))}}};")
        lines.append(f"static const dc_fun_t dco_term_force_tab[{nt}] = {{")
        lines += [f"  {_fun_entry(f'dcog_term{k}_force')}," for k in range(nt)]
        lines.append("};")
        lines.append(f"static const dc_fun_t dco_term_jac_tab[{nt}] = {{")
        lines += [f"  {_fun_entry(f'dcog_term{k}_jac')}," for k in range(nt)]
        lines.append("};")
    gaps_entry = _fun_entry("dcog_gaps") if spec.gaps is not None else _NO_FUN
    lines += [
        "const dco_model_t dco_model = {",
        f"  {spec.n}, {spec.m}, {nt}, {spec.n_gaps}, {spec.n_parameters},",
        f"  {'dco_n_params_tab' if nt else '0'},",
        f"  {_fun_entry('dcog_sys')},",
        f"  {_fun_entry('dcog_sys_jac')},",
        f"  {gaps_entry},",
        f"  {'dco_term_force_tab' if nt else '0'},",
        f"  {'dco_term_jac_tab' if nt else '0'},",
        (f"  {spec.outputs.numel_in(1)}, {spec.outputs.numel_in(3)}, {spec.outputs.numel_out(0)}, "
         f"{_fun_entry('dcog_outputs')}," if spec.outputs is not None else f"  0, 0, 0, {_NO_FUN},"),
        f"  {_c_string(spec.name)}",
        "};",
        "",
    ]
    return src + "\n".join(lines)


def build_ode_library(spec: OdeSpec) -> BuildResult:
    """Generate, compile (or find in the cache) the shared library of an OdeSpec.

    Same cache directory, key scheme and locking as :func:`build_model_library`; the library
    holds the generated functions and ``csrc/ode_driver.c`` (symbols ``dco_*``), and links
    nothing but libm.
    """
    t0 = time.perf_counter()
    source = generate_ode_source(spec)
    flags = [f"-DDCO_ABI_VERSION={ODE_DRIVER_ABI}", "-O2", "-fPIC", "-shared", "-fvisibility=hidden",
             "-Werror=incompatible-pointer-types", "-Werror=implicit-function-declaration"]
    driver = "".join(f"/* {name} */\n" + (CSRC / name).read_text() for name in ODE_DRIVER_SOURCES)
    return compile_cached("dco", f"the ODE model {spec.name!r}", source, "ode_driver.c", driver, flags, ["-lm"],
                          [], t0)
