"""C code generation and compilation of a DAE model for the compiled IDA backend.

``build_model_library(funcs)`` turns a :class:`daeclear.engine.ida_session.DAEFunctions` into a shared
library that holds

* the model's CasADi functions generated as C by ``casadi.CodeGenerator`` (symbols ``dc_res``,
  ``dc_jac``, ``dc_roots``, ``dc_term<k>_res``, ``dc_term<k>_jac``), every one normalised to dense
  column-vector inputs and a dense output (``casadi.densify``; the Jacobians column-major, as
  SUNDIALS' dense matrix stores them);
* a small generated table (``dc_model``: sizes, parameter counts, function pointers; layout in
  ``csrc/dc_model.h``);
* the hand-written driver ``csrc/ida_driver.c`` (IDA loop, callbacks, dense output);

linked against the SUNDIALS libraries shipped inside the scikit-sundae wheel
(``<site-packages>/scikit_sundae.libs``) by full path, with that directory as rpath (and ``-z defs``:
a function the libraries lack fails the link). The wheel has no SUNDIALS headers; the driver is
compiled against the real SUNDIALS headers of the wheel's release, vendored unmodified in
``csrc/sundials/include`` with a ``sundials_config.h`` describing the wheel's build (see
``csrc/sundials/README.md``). :func:`sundials_info` detects the wheel's SUNDIALS version and
``sunindextype`` width; they must equal the vendored headers' (:func:`vendored_sundials`, checked
before compiling) and are handed to the compiler (``-DDC_SUNDIALS_MAJOR=7 ... -DDC_INDEX_SIZE=32``),
where ``sundials_config.h`` checks them again with ``#error``. The sparse matrix and SuperLU_MT
libraries are linked too when the wheel has them (``-DDC_HAVE_SPARSE=1``: the sparse linear
solver of the driver).

Libraries are cached: the key is the SHA-256 of the generated source, the driver sources and
every vendored SUNDIALS header, the compiler command (with those flags) and version, the
SUNDIALS version and index size, and the SUNDIALS library paths. The cache directory is
``$DAECLEAR_CACHE_DIR`` or ``~/.cache/daeclear``. A build compiles into a private temporary
directory and moves the result into place with ``os.replace`` under a per-key file lock, so
concurrent processes building the same model neither corrupt nor duplicate each other's work.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import dataclasses
import hashlib
import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sysconfig
import tempfile
import time
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator

import casadi

from ..errors import AssemblyError, DaeclearError

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
]

CSRC = Path(__file__).resolve().parent / "csrc"
DRIVER_SOURCES = ("ida_driver.c", "dc_model.h", "dc_linalg.h")
#: The vendored SUNDIALS headers (csrc/sundials/README.md), the include path of the IDA driver;
#: every file of its parent folder is in the cache key.
SUNDIALS_INCLUDE = CSRC / "sundials" / "include"
SUNDIALS_LIBS = (
    "sundials_ida",
    "sundials_core",
    "sundials_nvecserial",
    "sundials_sunmatrixdense",
    "sundials_sunlinsoldense",
)
#: Linked when the wheel has both: the driver's sparse linear solver (SuperLU_MT on a
#: SUNSparseMatrix). SuperLU_MT's own BLAS and OpenMP libraries sit in the same folder.
SPARSE_LIBS = ("sundials_sunmatrixsparse", "sundials_sunlinsolsuperlumt")
#: The SUNDIALS major version of the vendored headers (their sundials_config.h #errors on any
#: other version than theirs; vendored_sundials reads the full one).
SUNDIALS_MAJOR = 7
#: Version of the ctypes interface of csrc/ida_driver.c, handed to the compiler (-DDC_ABI_VERSION)
#: and checked when a library is loaded: bump it when a dc_* signature changes.
DRIVER_ABI = 3
#: The same for csrc/ode_driver.c (-DDCO_ABI_VERSION).
ODE_DRIVER_ABI = 3
CFLAGS = (f"-DDC_ABI_VERSION={DRIVER_ABI}", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-Werror=incompatible-pointer-types",
          "-Werror=implicit-function-declaration", "-Wl,-z,defs")


class CompilerUnavailable(DaeclearError):
    """No working C compiler (or no SUNDIALS libraries) for the compiled backend."""


class CompileError(DaeclearError):
    """The C compiler failed on the generated model; the message holds its output."""


class SundialsMismatch(CompilerUnavailable):
    """The wheel's SUNDIALS libraries contradict themselves or a compiled library: its version or
    index size cannot be trusted, so the compiled backend is not used."""


# --------------------------------------------------------------------------- normalisation


@dataclass(frozen=True)
class NormalizedModel:
    """The model's functions with column-vector inputs, the run-time parameters ``P`` last.

    Signatures (sizes): ``res (1, n, n, n_P) -> n``; ``jac (1, n, n, 1, n_P) -> n x n``;
    ``term_res[k] (1, n, n, p_k, n_P) -> n``; ``term_jac[k] (1, n, n, p_k, 1, n_P) -> n x n``;
    ``roots (1, n, n, n_P) -> n_roots`` or None; ``extras[k] (..., n_P) -> vector``. Residuals,
    roots and extras have dense outputs; the Jacobians keep CasADi's sparsity (compressed
    column storage), so generated code grows with their nonzeros, not with n^2.
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
        ins = [casadi.MX.sym(f"i{k}", f.sparsity_in(k)) for k in range(f.n_in())]
        return casadi.Function(f.name() + "_dense", ins, [casadi.densify(f.call(ins)[0])])


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
    ins = [sym.sym(f"i{k}", f.sparsity_in(k)) for k in range(n_base)] + [sym.sym("P", n_parameters)]
    return casadi.Function(f.name(), ins, f.call(ins[:n_base]))


def _wrap(f: casadi.Function, name: str, in_sizes: list[int], out_shape: tuple[int, int],
          keep_sparsity: bool = False) -> casadi.Function:
    """Same function with column-vector inputs and an output of out_shape (dense unless
    ``keep_sparsity``)."""
    sym = casadi.SX if f.is_a("SXFunction") else casadi.MX
    ins = [sym.sym(f"i{k}", s) for k, s in enumerate(in_sizes)]
    args = [casadi.reshape(x, f.size_in(k)) for k, x in enumerate(ins)]
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
        tres.append(_wrap(fr, f"dc_term{k}_res", [1, n, n, p, n_P], (n, 1)))
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
        extras.append(_wrap(f, f"dc_extra{k}", sizes, (f.numel_out(0), 1)))
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


# --------------------------------------------------------------------------- toolchain


def compiler_command() -> list[str]:
    """The C compiler command: $CC, else sysconfig's CC, else cc/gcc. Raises CompilerUnavailable."""
    env_cc = os.environ.get("CC")
    candidates: list[tuple[str, str]] = []
    if env_cc is not None and env_cc.strip():
        candidates.append((env_cc, "$CC"))
    else:
        cfg = sysconfig.get_config_var("CC")
        if cfg:
            candidates.append((cfg, "sysconfig CC"))
        candidates += [("cc", "default"), ("gcc", "default")]
    tried = []
    for cmd, origin in candidates:
        parts = shlex.split(cmd)
        if not parts:
            continue
        exe = shutil.which(parts[0])
        if exe is not None:
            return [exe, *parts[1:]]
        tried.append(f"{parts[0]!r} ({origin})")
        if origin == "$CC":
            break  # an explicit $CC is not second-guessed
    raise CompilerUnavailable(f"no C compiler found: tried {', '.join(tried)}")


@functools.lru_cache(maxsize=16)
def _compiler_version(exe: str) -> str:
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
        return (out.stdout or out.stderr).strip().splitlines()[0] if (out.stdout or out.stderr) else ""
    except (OSError, subprocess.SubprocessError) as exc:
        raise CompilerUnavailable(f"C compiler {exe!r} does not run: {exc}") from exc


def _sksundae_dir() -> Path:
    spec = importlib.util.find_spec("sksundae")
    if spec is None or spec.origin is None:
        raise CompilerUnavailable("scikit-sundae (sksundae) is not installed")
    return Path(spec.origin).resolve().parent


@functools.lru_cache(maxsize=1)
def sundials_libraries() -> tuple[Path, dict[str, Path]]:
    """(directory, {name: path}) of the SUNDIALS shared libraries inside the scikit-sundae wheel:
    every one of ``SUNDIALS_LIBS``, and those of ``SPARSE_LIBS`` that are present."""
    libdir = _sksundae_dir().parent / "scikit_sundae.libs"
    if not libdir.is_dir():
        raise CompilerUnavailable(f"SUNDIALS libraries not found: {libdir} does not exist")
    found: dict[str, Path] = {}
    for name in SUNDIALS_LIBS + SPARSE_LIBS:
        hits = sorted(libdir.glob(f"lib{name}-*.so*"))
        if hits:
            found[name] = hits[0]
        elif name in SUNDIALS_LIBS:
            raise CompilerUnavailable(f"SUNDIALS library lib{name} not found in {libdir}")
    return libdir, found


@dataclass(frozen=True)
class SundialsInfo:
    """What the compiled driver depends on in the wheel's SUNDIALS build.

    ``version`` is major.minor.patch; ``index_size`` the width of ``sunindextype`` in bits (32 or
    64), which sizes every vector, matrix and sparse index the driver hands to SUNDIALS;
    ``has_sparse`` whether the sparse matrix and SuperLU_MT libraries are there.
    """

    version: str
    index_size: int
    has_sparse: bool

    @property
    def version_tuple(self) -> tuple[int, int, int]:
        major, minor, patch = (int(x) for x in self.version.split("."))
        return major, minor, patch

    def compile_flags(self) -> list[str]:
        """The -D flags that tell the vendored sundials_config.h and csrc/ida_driver.c what they
        build for (the header #errors when they disagree with it)."""
        major, minor, patch = self.version_tuple
        return [f"-DDC_SUNDIALS_MAJOR={major}", f"-DDC_SUNDIALS_MINOR={minor}", f"-DDC_SUNDIALS_PATCH={patch}",
                f"-DDC_INDEX_SIZE={self.index_size}", f"-DDC_HAVE_SPARSE={int(self.has_sparse)}"]


#: C spellings of sunindextype in c_config.pxi (Linux, LP64) and their width in bits
_INDEX_TYPES = {"int": 32, "int32_t": 32, "long": 64, "long int": 64, "long long": 64, "long long int": 64,
                "int64_t": 64}


def parse_index_size(text: str, source: str = "c_config.pxi") -> int | None:
    """Width in bits of ``sunindextype`` declared in scikit-sundae's ``c_config.pxi`` (``ctypedef
    int sunindextype``); None when the file declares none; CompilerUnavailable for a type that is
    not a known 32- or 64-bit integer (guessing would corrupt memory)."""
    m = re.search(r"^\s*ctypedef\s+([A-Za-z_][\w ]*?)\s+sunindextype\s*(?:#.*)?$", text, re.MULTILINE)
    if m is None:
        return None
    decl = " ".join(m.group(1).split())
    if decl not in _INDEX_TYPES:
        raise CompilerUnavailable(f"{source} declares sunindextype as {decl!r}, which is not one of "
                                  f"{', '.join(sorted(_INDEX_TYPES))}: cannot tell the SUNDIALS index size")
    return _INDEX_TYPES[decl]


_CONFIG_MACRO = re.compile(r"^#define (SUNDIALS_VERSION_MAJOR|SUNDIALS_VERSION_MINOR|SUNDIALS_VERSION_PATCH|"
                           r"SUNDIALS_INT32_T|SUNDIALS_INT64_T)\b\s*(\d*)", re.MULTILINE)


def vendored_sundials() -> tuple[str, int]:
    """(version, sunindextype bits) of the vendored SUNDIALS headers, read from their
    ``sundials_config.h``; CompilerUnavailable when the file is missing or says neither."""
    config = SUNDIALS_INCLUDE / "sundials" / "sundials_config.h"
    try:
        macros = dict(_CONFIG_MACRO.findall(config.read_text()))
    except OSError as exc:
        raise CompilerUnavailable(f"the vendored SUNDIALS headers are missing: {config} ({exc})") from exc
    parts = [macros.get(f"SUNDIALS_VERSION_{x}", "") for x in ("MAJOR", "MINOR", "PATCH")]
    widths = [bits for bits in (32, 64) if f"SUNDIALS_INT{bits}_T" in macros]
    if not all(parts) or len(widths) != 1:
        raise CompilerUnavailable(f"{config} defines no SUNDIALS version or no single index type")
    return ".".join(parts), widths[0]


def check_vendored(info: SundialsInfo) -> None:
    """SundialsMismatch unless the wheel's SUNDIALS (version, index width) is the one the vendored
    headers describe: compiling the driver against other headers would corrupt memory."""
    version, bits = vendored_sundials()
    if (info.version, info.index_size) != (version, bits):
        raise SundialsMismatch(
            f"the installed scikit-sundae has SUNDIALS {info.version} with a {info.index_size}-bit sunindextype, "
            f"but daeclear's vendored SUNDIALS headers (daeclear/engine/csrc/sundials) are version {version} with a "
            f"{bits}-bit sunindextype: install the scikit-sundae release built on SUNDIALS {version}, or vendor "
            f"the headers of SUNDIALS {info.version} (csrc/sundials/README.md says how)")


def _version_from_name(path: Path) -> str | None:
    """``libsundials_core-<hash>.so.7.9.0`` -> "7.9.0" (the core library's version is SUNDIALS')."""
    m = re.search(r"\.so\.(\d+)\.(\d+)\.(\d+)$", path.name)
    return ".".join(m.groups()) if m else None


def _version_from_library(core: Path) -> str | None:
    """SUNDIALSGetVersionNumber of the core library, or None when it cannot be called."""
    try:
        lib = ctypes.CDLL(str(core))
        fn = lib.SUNDIALSGetVersionNumber
    except (OSError, AttributeError):
        return None
    parts = [ctypes.c_int(-1) for _ in range(3)]
    label = ctypes.create_string_buffer(64)
    fn.restype = ctypes.c_int
    fn.argtypes = [ctypes.POINTER(ctypes.c_int)] * 3 + [ctypes.c_char_p, ctypes.c_int]
    if fn(*(ctypes.byref(x) for x in parts), label, 64) != 0 or min(x.value for x in parts) < 0:
        return None
    return ".".join(str(x.value) for x in parts)


def _probe_index_size(libs: dict[str, Path]) -> int | None:
    """Width of sunindextype the libraries were really built with, or None if it cannot be probed.

    Public API only: a dense 2 x 2 matrix converted to CSC has column pointers [0, 2, 4]; read as
    32-bit integers they are [0, 2, 4] in an int32 build and [0, 0, 2] in an int64 one. The
    sizes are passed as 64-bit values, which either build reads correctly (x86-64 registers).
    """
    try:
        core = ctypes.CDLL(str(libs["sundials_core"]))
        dense = ctypes.CDLL(str(libs["sundials_sunmatrixdense"]))
        sparse = ctypes.CDLL(str(libs["sundials_sunmatrixsparse"]))
    except (OSError, KeyError):
        return None
    V = ctypes.c_void_p
    core.SUNContext_Create.argtypes = [ctypes.c_int, ctypes.POINTER(V)]
    core.SUNContext_Free.argtypes = [ctypes.POINTER(V)]
    core.SUNMatDestroy.argtypes = [V]
    core.SUNMatDestroy.restype = None
    dense.SUNDenseMatrix.argtypes = [ctypes.c_int64, ctypes.c_int64, V]
    dense.SUNDenseMatrix.restype = V
    dense.SUNDenseMatrix_Data.argtypes = [V]
    dense.SUNDenseMatrix_Data.restype = ctypes.POINTER(ctypes.c_double)
    sparse.SUNSparseFromDenseMatrix.argtypes = [V, ctypes.c_double, ctypes.c_int]
    sparse.SUNSparseFromDenseMatrix.restype = V
    sparse.SUNSparseMatrix_IndexPointers.argtypes = [V]
    sparse.SUNSparseMatrix_IndexPointers.restype = ctypes.POINTER(ctypes.c_int32)
    ctx = V()
    if core.SUNContext_Create(0, ctypes.byref(ctx)) != 0 or not ctx.value:
        return None
    A = B = None
    try:
        A = dense.SUNDenseMatrix(2, 2, ctx)
        if not A:
            return None
        data = dense.SUNDenseMatrix_Data(A)
        for i in range(4):
            data[i] = 1.0
        B = sparse.SUNSparseFromDenseMatrix(A, 0.0, 0)  # CSC_MAT
        if not B:
            return None
        ptr = sparse.SUNSparseMatrix_IndexPointers(B)
        words = [ptr[i] for i in range(3)]
        return {(0, 2, 4): 32, (0, 0, 2): 64}.get(tuple(words))
    finally:
        for M in (B, A):
            if M:
                core.SUNMatDestroy(M)
        core.SUNContext_Free(ctypes.byref(ctx))


_BUILD_TAG = re.compile(rb"daeclear-build:abi=(\d+);sundials=(\d+)\.(\d+)\.(\d+);index=(\d+);sparse=(\d);")


def read_build_tag(path: Path) -> tuple[int, SundialsInfo] | None:
    """(driver ABI, SUNDIALS build) a compiled model library was made for, read from the file's
    bytes (the driver's ``dc_build_tag``) without loading it; None when it has no tag."""
    data = path.read_bytes()
    start = data.find(b"daeclear-build:")
    m = _BUILD_TAG.match(data, start) if start >= 0 else None
    if m is None:
        return None
    abi, major, minor, patch, index, sparse = (int(x) for x in m.groups())
    return abi, SundialsInfo(f"{major}.{minor}.{patch}", index, bool(sparse))


@functools.lru_cache(maxsize=1)
def sundials_info() -> SundialsInfo:
    """Detect the SUNDIALS version and index size of the wheel's libraries (once per process).

    Version: from the core library's file name (``.so.7.9.0``) and from
    ``SUNDIALSGetVersionNumber`` of that library; both must agree when both are known.
    Index size: ``sunindextype`` in ``sksundae/c_config.pxi``, cross-checked on the libraries
    themselves (:func:`_probe_index_size`); when the file is missing or silent the probe alone
    decides. Whatever cannot be determined, or contradicts itself, raises CompilerUnavailable
    (SundialsMismatch): the compiled backend is then not used, never built on a guess.
    """
    _, libs = sundials_libraries()
    core = libs["sundials_core"]
    named, reported = _version_from_name(core), _version_from_library(core)
    if named and reported and named != reported:
        raise SundialsMismatch(f"{core.name} is named for SUNDIALS {named} but reports version {reported}")
    version = reported or named
    if version is None:
        raise CompilerUnavailable(f"cannot determine the SUNDIALS version of {core}: no version in its name "
                                  "and SUNDIALSGetVersionNumber could not be called")
    pxi = _sksundae_dir() / "c_config.pxi"
    declared = parse_index_size(pxi.read_text(), str(pxi)) if pxi.is_file() else None
    probed = _probe_index_size(libs)
    if declared is not None and probed is not None and declared != probed:
        raise SundialsMismatch(f"{pxi} declares a {declared}-bit sunindextype but the SUNDIALS libraries in "
                               f"{core.parent} use {probed}-bit indices")
    index_size = declared if declared is not None else probed
    if index_size is None:
        raise CompilerUnavailable(f"cannot determine the SUNDIALS index size (sunindextype): {pxi} "
                                  f"{'declares none' if pxi.is_file() else 'does not exist'} and probing the "
                                  "libraries failed")
    return SundialsInfo(version, index_size, all(name in libs for name in SPARSE_LIBS))


def cache_dir() -> Path:
    d = os.environ.get("DAECLEAR_CACHE_DIR")
    return Path(d).expanduser() if d else Path.home() / ".cache" / "daeclear"


# --------------------------------------------------------------------------- build


@dataclass(frozen=True)
class BuildResult:
    path: Path
    key: str
    cache_hit: bool
    compile_time: float   # s spent in the compiler (0 on a cache hit)
    codegen_time: float   # s spent generating C and hashing


@contextlib.contextmanager
def _file_lock(path: Path) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # pragma: no cover - non-POSIX
        yield
        return
    with open(path, "a+") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def _driver_text() -> str:
    """The driver sources and every vendored SUNDIALS file, as a SHA-256 for the cache key:
    editing any of them builds again. Files are read again only when one's size or mtime moved."""
    files = [CSRC / name for name in DRIVER_SOURCES]
    files += sorted(p for p in SUNDIALS_INCLUDE.parent.rglob("*") if p.is_file())
    stats = [(p, p.stat()) for p in files]
    return _files_digest(tuple((str(p), st.st_mtime_ns, st.st_size) for p, st in stats))


@functools.lru_cache(maxsize=8)
def _files_digest(stamps: tuple[tuple[str, int, int], ...]) -> str:
    h = hashlib.sha256()
    for name, _, _ in stamps:
        path = Path(name)
        h.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
    return "driver sources sha256 " + h.hexdigest()


MemoTable = dict[Any, Any]
_MEMO_TABLES: list[MemoTable] = []


def memo_table() -> MemoTable:
    """A new in-process memo (by object identity with memo_get/memo_put, or by any key);
    :func:`clear_memos` empties them all."""
    table: MemoTable = {}
    _MEMO_TABLES.append(table)
    return table


def clear_memos() -> None:
    """Forget every assembled template, normalised model, generated spec and loaded library of
    this process (the disk cache stays): the next run generates and loads again, e.g. after changing ``$CC``."""
    for table in _MEMO_TABLES:
        table.clear()


def memo_get(table: MemoTable, obj: Any) -> Any:
    """The value memoised for this very object (identity, kept only while the object lives)."""
    entry = table.get(id(obj))
    return entry[1] if entry is not None and entry[0]() is obj else None


def memo_put(table: MemoTable, obj: Any, value: Any) -> None:
    try:
        ref = weakref.ref(obj, lambda _r, key=id(obj): table.pop(key, None))
    except TypeError:
        return
    table[id(obj)] = (ref, value)


# Libraries already built in this process, by DAEFunctions identity (shared by every model of
# one structure): simulating again skips code generation (tens of ms) as well as compilation.
_BUILT = memo_table()


def build_model_library(funcs: Any, *, model: NormalizedModel | None = None) -> BuildResult:
    """Generate, compile (or find in the cache) the shared library for a DAEFunctions."""
    known = memo_get(_BUILT, funcs)
    if known is not None and known.path.exists():
        return dataclasses.replace(known, cache_hit=True, compile_time=0.0, codegen_time=0.0)
    result = _build_model_library(funcs, model=model)
    memo_put(_BUILT, funcs, result)
    return result


def _build_model_library(funcs: Any, *, model: NormalizedModel | None = None) -> BuildResult:
    t0 = time.perf_counter()
    if model is None:
        model = normalize_model(funcs)
    libdir, libs = sundials_libraries()
    info = sundials_info()
    check_vendored(info)
    names = SUNDIALS_LIBS + (SPARSE_LIBS if info.has_sparse else ())
    source = generate_source(model)
    link = [str(libs[name]) for name in names] + [f"-Wl,-rpath,{libdir}", "-lm"]
    flags = [*CFLAGS, f"-I{SUNDIALS_INCLUDE}", *info.compile_flags()]
    gomp = sorted(libdir.glob("libgomp-*.so*")) if info.has_sparse else []
    if gomp:  # SuperLU_MT's OpenMP runtime: the driver keeps its teams at one thread
        link.insert(len(names), str(gomp[0]))
        flags.append("-DDC_SUPERLUMT_OMP=1")
    # the -D flags are hashed with the command; version and index size are named in the key too
    key = [f"SUNDIALS {info.version} sunindextype {info.index_size}-bit sparse {int(info.has_sparse)}",
           "\n".join(str(libs[name]) for name in names)]
    return compile_cached("dc", f"the model {model.name!r}", source, "ida_driver.c", _driver_text(), flags, link,
                          key, t0)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _intact(library: Path, digest: Path) -> bool:
    """The cached library exists and is byte for byte the one that was built (a truncated or
    damaged file would crash the interpreter when loaded)."""
    try:
        return library.is_file() and digest.read_text().strip() == _sha256(library)
    except OSError:
        return False


def compile_cached(prefix: str, what: str, source: str, driver: str, driver_text: str, flags: list[str],
                   link: list[str], extra_key: list[str], t0: float) -> BuildResult:
    """Compile ``source`` with the driver ``csrc/<driver>`` into a cached shared library.

    The cache key hashes the generated source, the driver sources, the compiler command and
    version and ``extra_key``; the library is built in a temporary directory under a file lock
    and moved into place atomically, so concurrent processes never see a half-written file. Its
    SHA-256 is kept beside it (``<stem>.sha256``) and checked before a cached library is used: a
    truncated or damaged file is built again, never loaded.
    ``t0`` is when code generation started (reported as ``codegen_time``).
    """
    cc = compiler_command()
    version = _compiler_version(cc[0])
    flags = [*flags, f"-I{CSRC}"]
    h = hashlib.sha256()
    for part in (prefix, source, driver_text, shlex.join(cc + flags + link), version, *extra_key):
        h.update(part.encode())
        h.update(b"\0")
    key = h.hexdigest()
    codegen_time = time.perf_counter() - t0

    root = cache_dir()
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CompilerUnavailable(f"cache directory {root} cannot be created: {exc}") from exc
    stem = f"{prefix}_{key[:40]}"
    target = root / f"{stem}.so"
    digest = root / f"{stem}.sha256"
    if _intact(target, digest):
        return BuildResult(target, key, True, 0.0, codegen_time)
    with _file_lock(root / f"{stem}.lock"):
        if _intact(target, digest):  # built by another process meanwhile
            return BuildResult(target, key, True, 0.0, codegen_time)
        target.unlink(missing_ok=True)  # absent, truncated or altered: never loaded, built again
        t1 = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix=f"{stem}-", dir=root) as tmp:
            tmpd = Path(tmp)
            model_c = tmpd / "model.c"
            model_c.write_text(source)
            out = tmpd / "lib.so"
            cmd = [*cc, *flags, str(model_c), str(CSRC / driver), "-o", str(out), *link]
            try:
                proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
            except (OSError, subprocess.SubprocessError) as exc:
                raise CompilerUnavailable(f"running the C compiler {cc[0]!r} failed: {exc}") from exc
            if proc.returncode != 0 or not out.is_file():
                msg = (proc.stderr or proc.stdout or "").strip()
                if len(msg) > 4000:
                    msg = msg[:2000] + "\n...\n" + msg[-2000:]
                raise CompileError(f"compiling {what} failed (exit {proc.returncode}):\n$ {shlex.join(cmd)}\n{msg}")
            # keep the generated source next to the library, for debugging
            src_tmp = tmpd / "src.c"
            src_tmp.write_text(source)
            os.replace(src_tmp, root / f"{stem}.c")
            digest_tmp = tmpd / "lib.sha256"
            digest_tmp.write_text(_sha256(out))
            os.replace(digest_tmp, digest)  # the digest first: a library is never there without it
            os.replace(out, target)
        return BuildResult(target, key, False, time.perf_counter() - t1, codegen_time)


# --------------------------------------------------------------------------- ODE libraries
# (for the explicit and scipy integrators of daeclear.solvers.explicit; no SUNDIALS involved)

ODE_DRIVER_SOURCES = ("ode_driver.c", "dco_model.h", "dc_model.h", "dc_linalg.h")
__all__ += ["OdeSpec", "generate_ode_source", "build_ode_library"]


@dataclass(frozen=True)
class OdeSpec:
    """An index-1 mechanism as an ODE in x = (q, v), as CasADi functions for ``csrc/ode_driver.c``.

    Sizes: n coordinates, m constraints. Every function has dense column-vector inputs; matrix
    outputs are dense (stored column-major in C):

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
        for i in range(f.n_out()):
            if not f.sparsity_out(i).is_dense():
                raise AssemblyError(f"OdeSpec.{what} ({f.name()}): output {i} must be dense")

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
            raise AssemblyError("OdeSpec.outputs must be a casadi.Function (t[1], y[n_y], yp[n_y], switch, P) -> channels")


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
        ins = [casadi.SX.sym(f"i{i}", f.numel_in(i)) if f.is_a("SXFunction") else
               casadi.MX.sym(f"i{i}", f.numel_in(i)) for i in range(f.n_in())]
        args = [casadi.reshape(x, f.size_in(i)) for i, x in enumerate(ins)]
        outs = [casadi.densify(o) for o in f.call(args)]
        cg.add(casadi.Function(name, ins, outs))
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
