"""The SUNDIALS of the scikit-sundae wheel, as the compiled IDA driver depends on it: its libraries
(:func:`sundials_libraries`), their version and ``sunindextype`` width (:func:`sundials_info`), the
vendored headers that must describe that same build (:func:`vendored_sundials`, :func:`check_vendored`;
the wheel has no headers, ``csrc/sundials/README.md``) and a library's build tag (:func:`read_build_tag`).
A wrong index width would be silent memory corruption, so nothing here guesses.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.util
import re
from dataclasses import dataclass
from pathlib import Path

from .build import CSRC, CompilerUnavailable

__all__ = ["SUNDIALS_INCLUDE", "SUNDIALS_LIBS", "SPARSE_LIBS", "SUNDIALS_MAJOR", "SundialsInfo", "SundialsMismatch",
           "sundials_libraries", "sundials_info", "parse_index_size", "vendored_sundials", "check_vendored",
           "read_build_tag"]

#: The vendored SUNDIALS headers (csrc/sundials/README.md): the IDA driver's include path, in the cache key.
SUNDIALS_INCLUDE = CSRC / "sundials" / "include"
SUNDIALS_LIBS = ("sundials_ida", "sundials_core", "sundials_nvecserial", "sundials_sunmatrixdense",
                 "sundials_sunlinsoldense")
#: Linked when the wheel has both: the driver's sparse linear solver (SuperLU_MT on a SUNSparseMatrix).
SPARSE_LIBS = ("sundials_sunmatrixsparse", "sundials_sunlinsolsuperlumt")
#: The SUNDIALS major version of the vendored headers (vendored_sundials reads the full one).
SUNDIALS_MAJOR = 7


class SundialsMismatch(CompilerUnavailable):
    """The wheel's SUNDIALS libraries contradict themselves or a compiled library: its version or
    index size cannot be trusted, so the compiled backend is not used."""


def _sksundae_dir() -> Path:
    spec = importlib.util.find_spec("sksundae")
    if spec is None or spec.origin is None:
        raise CompilerUnavailable("scikit-sundae (sksundae) is not installed")
    return Path(spec.origin).resolve().parent


@functools.lru_cache(maxsize=1)
def sundials_libraries() -> tuple[Path, dict[str, Path]]:
    """(directory, {name: path}) of the wheel's SUNDIALS libraries: ``SUNDIALS_LIBS`` and those of
    ``SPARSE_LIBS`` that are present."""
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
    """What the driver depends on in the wheel's SUNDIALS: ``version`` (major.minor.patch), ``index_size``
    (bits of ``sunindextype``), ``has_sparse`` (the sparse matrix and SuperLU_MT libraries are there)."""

    version: str
    index_size: int
    has_sparse: bool

    @property
    def version_tuple(self) -> tuple[int, int, int]:
        major, minor, patch = (int(x) for x in self.version.split("."))
        return major, minor, patch

    def compile_flags(self) -> list[str]:
        """The -D flags that tell the vendored sundials_config.h (which #errors on a mismatch) and
        csrc/ida_driver.c what they build for."""
        major, minor, patch = self.version_tuple
        return [f"-DDC_SUNDIALS_MAJOR={major}", f"-DDC_SUNDIALS_MINOR={minor}", f"-DDC_SUNDIALS_PATCH={patch}",
                f"-DDC_INDEX_SIZE={self.index_size}", f"-DDC_HAVE_SPARSE={int(self.has_sparse)}"]


#: C spellings of sunindextype in c_config.pxi (Linux, LP64) and their width in bits
_INDEX_TYPES = {"int": 32, "int32_t": 32, "long": 64, "long int": 64, "long long": 64, "long long int": 64,
                "int64_t": 64}


def parse_index_size(text: str, source: str = "c_config.pxi") -> int | None:
    """Width in bits of ``sunindextype`` in scikit-sundae's ``c_config.pxi``; None when it declares
    none; CompilerUnavailable for a type not known as a 32- or 64-bit integer."""
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
    """SundialsMismatch unless the wheel's SUNDIALS (version, index width) is the vendored headers'."""
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
    """Width of sunindextype the libraries were really built with, or None if it cannot be probed:
    a dense 2 x 2 matrix converted to CSC has column pointers [0, 2, 4], read as 32-bit integers
    [0, 2, 4] in an int32 build and [0, 0, 2] in an int64 one (sizes passed as 64-bit values,
    which either build reads correctly on x86-64)."""
    try:
        core = ctypes.CDLL(str(libs["sundials_core"]))
        dense = ctypes.CDLL(str(libs["sundials_sunmatrixdense"]))
        sparse = ctypes.CDLL(str(libs["sundials_sunmatrixsparse"]))
    except (OSError, KeyError):
        return None
    V = ctypes.c_void_p
    for lib, name, restype, argtypes in (
            (core, "SUNContext_Create", ctypes.c_int, [ctypes.c_int, ctypes.POINTER(V)]),
            (core, "SUNContext_Free", ctypes.c_int, [ctypes.POINTER(V)]),
            (core, "SUNMatDestroy", None, [V]),
            (dense, "SUNDenseMatrix", V, [ctypes.c_int64, ctypes.c_int64, V]),
            (dense, "SUNDenseMatrix_Data", ctypes.POINTER(ctypes.c_double), [V]),
            (sparse, "SUNSparseFromDenseMatrix", V, [V, ctypes.c_double, ctypes.c_int]),
            (sparse, "SUNSparseMatrix_IndexPointers", ctypes.POINTER(ctypes.c_int32), [V])):
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes
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
        return {(0, 2, 4): 32, (0, 0, 2): 64}.get((ptr[0], ptr[1], ptr[2]))
    finally:
        for M in (B, A):
            if M:
                core.SUNMatDestroy(M)
        core.SUNContext_Free(ctypes.byref(ctx))


_BUILD_TAG = re.compile(rb"daeclear-build:abi=(\d+);sundials=(\d+)\.(\d+)\.(\d+);index=(\d+);sparse=(\d);")


def read_build_tag(path: Path) -> tuple[int, SundialsInfo] | None:
    """(driver ABI, SUNDIALS build) of a compiled model library, read from the file (``dc_build_tag``)
    without loading it; None when it has no tag."""
    data = path.read_bytes()
    start = data.find(b"daeclear-build:")
    m = _BUILD_TAG.match(data, start) if start >= 0 else None
    if m is None:
        return None
    abi, major, minor, patch, index, sparse = (int(x) for x in m.groups())
    return abi, SundialsInfo(f"{major}.{minor}.{patch}", index, bool(sparse))


@functools.lru_cache(maxsize=1)
def sundials_info() -> SundialsInfo:
    """The SUNDIALS version (the core library's file name and ``SUNDIALSGetVersionNumber``) and index
    size (``sksundae/c_config.pxi`` and :func:`_probe_index_size`) of the wheel, once per process; either
    unknown or contradictory raises CompilerUnavailable (SundialsMismatch), never a guess."""
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

