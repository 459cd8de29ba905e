"""The SUNDIALS of the scikit-sundae wheel, as the compiled IDA driver depends on it.

Where its shared libraries are (:func:`sundials_libraries`), which version and ``sunindextype``
width they have (:func:`sundials_info`, detected once per process), the vendored SUNDIALS headers
that must describe that same build (:func:`vendored_sundials`, :func:`check_vendored`), and the
build tag a compiled model library carries (:func:`read_build_tag`). Separate from compiling
(:mod:`daeclear.engine.build`) because it is only about the wheel: a wrong index width would be
silent memory corruption, so nothing here guesses.

The wheel has no SUNDIALS headers; the driver is compiled against the real SUNDIALS headers of the
wheel's release, vendored unmodified in ``csrc/sundials/include`` with a ``sundials_config.h``
describing the wheel's build (see ``csrc/sundials/README.md``).
"""

from __future__ import annotations

import ctypes
import functools
import importlib.util
import re
from dataclasses import dataclass
from pathlib import Path

from .build import CSRC, CompilerUnavailable

__all__ = [
    "SUNDIALS_INCLUDE",
    "SUNDIALS_LIBS",
    "SPARSE_LIBS",
    "SUNDIALS_MAJOR",
    "SundialsInfo",
    "SundialsMismatch",
    "sundials_libraries",
    "sundials_info",
    "parse_index_size",
    "vendored_sundials",
    "check_vendored",
    "read_build_tag",
]

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

