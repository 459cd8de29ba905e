"""Loading compiled libraries: the one place that opens a built shared library with ctypes.

Declares the functions from the table that also declares them to C (:mod:`daeclear.engine.c_api`) and
checks the driver ABI and, for an IDA model library (:class:`ModelLibrary`), the SUNDIALS build (the
file's build tag before loading, then ``dc_build_info`` and ``SUNDIALSGetVersion``); one that must not
run is unloaded (:class:`StaleLibrary`).
:class:`OdeLibrary`: the ODE evaluator of :mod:`daeclear.solvers.explicit`.
"""

from __future__ import annotations

import ctypes
import re
from pathlib import Path
from typing import Any, ClassVar
from collections.abc import Mapping, Sequence

from . import c_api, sundials
from .abi import DC_BI_INDEX_BITS, DC_BI_INDEX_SIZE, DC_BI_MAJOR, DC_BI_MINOR, DC_BI_N, DC_BI_PATCH, DC_BI_SPARSE
from ..core.errors import DaeclearError
from .sundials import SundialsInfo

__all__ = ["DRIVER_ABI", "ODE_DRIVER_ABI", "Prototypes", "StaleLibrary", "open_library", "unload", "LoadedLibrary",
           "ModelLibrary", "OdeLibrary"]

#: Version of the ctypes interface of csrc/ida_driver.c, handed to the compiler (-DDC_ABI_VERSION)
#: and checked when a library is loaded: bump it when a dc_* signature (c_api.py) or what a dc_* call writes
#: changes.
DRIVER_ABI = 10
#: The same for csrc/ode_driver.c (-DDCO_ABI_VERSION).
ODE_DRIVER_ABI = 3

#: A prototype table: C function name -> (restype, argtypes), as ctypes declares them.
Prototypes = Mapping[str, tuple[Any, Sequence[Any]]]

#: The dc_* functions of csrc/ida_driver.c, from the table that also declares them to C (c_api.py).
MODEL_PROTOTYPES: Prototypes = c_api.prototypes(c_api.IDA_ENTRY_POINTS)
#: The dco_* functions of csrc/ode_driver.c.
ODE_PROTOTYPES: Prototypes = c_api.prototypes(c_api.ODE_ENTRY_POINTS)


class StaleLibrary(DaeclearError):
    """A cached library was built for another driver ABI or SUNDIALS build than this one: it must not run."""


def open_library(path: Path, prototypes: Prototypes) -> ctypes.CDLL:
    """dlopen ``path`` and declare every function of ``prototypes`` (restype, argtypes) on it."""
    lib = ctypes.CDLL(str(path))
    for name, (restype, argtypes) in prototypes.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, list(argtypes)
    return lib


def unload(lib: ctypes.CDLL) -> None:
    """dlclose a library that must not be used (dlopen of a path still open returns the old library)."""
    import _ctypes

    _ctypes.dlclose(lib._handle)


def _version_prefix(text: str) -> str:
    m = re.match(r"\d+\.\d+\.\d+", text)
    return m.group(0) if m else text


def _staleness(built: SundialsInfo, current: SundialsInfo) -> str | None:
    """Why a library built for the SUNDIALS ``built`` must not run with ``current``; None if it may."""
    if (built.version, built.index_size) != (current.version, current.index_size):
        return (f"built for SUNDIALS {built.version} with {built.index_size}-bit indices, but the wheel has "
                f"SUNDIALS {current.version} with {current.index_size}-bit indices")
    if built.has_sparse != current.has_sparse:
        return (f"built {'with' if built.has_sparse else 'without'} the sparse solver libraries, which the wheel "
                f"{'has' if current.has_sparse else 'lacks'} now")
    return None


def _check_loaded(lib: ctypes.CDLL, tagged: SundialsInfo) -> tuple[SundialsInfo, str, str | None]:
    """(build info, SUNDIALSGetVersion, problem or None): dc_build_info must be the tag's, and the SUNDIALS
    it resolved (LD_LIBRARY_PATH may find another) the version it was built for."""
    buf = ctypes.create_string_buffer(64)
    lib.dc_sundials_version(buf, 64)
    loaded = buf.value.decode()
    raw = (ctypes.c_int * DC_BI_N)()
    lib.dc_build_info(raw, DC_BI_N)
    info = SundialsInfo(f"{raw[DC_BI_MAJOR]}.{raw[DC_BI_MINOR]}.{raw[DC_BI_PATCH]}", raw[DC_BI_INDEX_SIZE],
                        bool(raw[DC_BI_SPARSE]))
    bits = raw[DC_BI_INDEX_BITS]
    if info != tagged or bits != info.index_size:
        return info, loaded, (f"its dc_build_info ({info}, sunindextype {bits} bits) contradicts its build tag "
                              f"({tagged})")
    if _version_prefix(loaded) != info.version:
        return info, loaded, f"built for SUNDIALS {info.version}, but the SUNDIALS it loads reports version {loaded!r}"
    return info, loaded, None


class LoadedLibrary:
    """ctypes view (``lib``) of one compiled library, opened once per process and path by :meth:`load`."""

    PROTOTYPES: ClassVar[Prototypes] = {}
    _cache: ClassVar[dict[str, Any]] = {}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._cache = {}  # one cache per kind of library

    def __init__(self, path: Path) -> None:
        self.path = path
        self.lib = open_library(path, self.PROTOTYPES)

    @classmethod
    def load(cls, path: Path) -> Any:
        """The library at ``path``, opened (and checked) on the first call of this process."""
        key = str(path)
        if key not in cls._cache:
            cls._cache[key] = cls(path)
        return cls._cache[key]


class ModelLibrary(LoadedLibrary):
    """ctypes view of one compiled IDA model library (shared by all its sessions); StaleLibrary when
    its build tag (:func:`_staleness`) or, once loaded, its build info (:func:`_check_loaded`) does
    not fit, then unloaded before any call into SUNDIALS."""

    PROTOTYPES = MODEL_PROTOTYPES

    def __init__(self, path: Path) -> None:
        tag = sundials.read_build_tag(path)
        if tag is None:
            raise StaleLibrary(f"{path}: no daeclear build tag (built by another daeclear version)")
        abi, tagged = tag
        if abi != DRIVER_ABI:
            raise StaleLibrary(f"{path}: driver ABI version {abi} != {DRIVER_ABI}")
        why = _staleness(tagged, sundials.sundials_info())
        if why is not None:
            raise StaleLibrary(f"{path}: {why}")
        super().__init__(path)
        lib = self.lib
        abi = lib.dc_abi_version()
        if abi != DRIVER_ABI:
            unload(lib)
            raise StaleLibrary(f"{path}: driver ABI version {abi} != {DRIVER_ABI} (build tag said {DRIVER_ABI})")
        info, loaded, why = _check_loaded(lib, tagged)
        if why is not None:
            unload(lib)
            raise StaleLibrary(f"{path}: {why}")
        self.build_info: SundialsInfo = info  # what it was compiled for
        self.sundials_version = loaded  # SUNDIALSGetVersion of the SUNDIALS it loaded
        plan = (ctypes.c_longlong * 3)()
        lib.dc_sparse_plan(ctypes.addressof(plan), 3)
        #: whether the model has a sparse LU plan, and its union and L + U nonzeros (dc_sparse_plan)
        self.sparse_plan: tuple[bool, int, int] = (bool(plan[0]), int(plan[1]), int(plan[2]))

    def model_info(self, n_terms: int) -> tuple[int, int, int, list[int]]:
        """(n, terms, roots, parameters per term) of the compiled model."""
        n, nt, nr = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        np_ = (ctypes.c_int * max(n_terms, 1))()
        self.lib.dc_model_info(ctypes.addressof(n), ctypes.addressof(nt), ctypes.addressof(nr),
                               ctypes.addressof(np_))
        return n.value, nt.value, nr.value, list(np_)[: nt.value]

    def flag_name(self, flag: int) -> str:
        """SUNDIALS' name of an IDA return flag."""
        buf = ctypes.create_string_buffer(64)
        self.lib.dc_flag_name(flag, buf, 64)
        return buf.value.decode()


class OdeLibrary(LoadedLibrary):
    """ctypes view of one compiled ODE library (csrc/ode_driver.c); a library built for another
    ODE driver ABI raises DaeclearError."""

    PROTOTYPES = ODE_PROTOTYPES

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        lib = self.lib
        if lib.dco_abi_version() != ODE_DRIVER_ABI:
            raise DaeclearError(f"{path}: ODE driver ABI version {lib.dco_abi_version()} != {ODE_DRIVER_ABI}")
