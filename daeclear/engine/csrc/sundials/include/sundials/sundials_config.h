/* sundials_config.h -- written by daeclear, not part of the SUNDIALS release.
 *
 * SUNDIALS' CMake build generates this file from include/sundials/sundials_config.in. This one
 * describes the SUNDIALS build inside the scikit-sundae 1.2.0 wheel
 * (<site-packages>/scikit_sundae.libs), which ships the libraries but no headers:
 *
 *   version        7.9.0 (release tag v7.9.0, commit 312fc0f3684f): the libraries' file names
 *                  (libsundials_core-*.so.7.9.0) and SUNDIALSGetVersionNumber;
 *   sunrealtype    double;
 *   sunindextype   int32_t: sksundae/c_config.pxi (ctypedef int sunindextype) and a probe of
 *                  the libraries (daeclear.codegen.sundials_info);
 *   no MPI         no MPI symbol or library in the wheel;
 *   modules        those with a library in the wheel (SUNDIALS_<MODULE> below); SuperLU_MT
 *                  runs on OpenMP (libsundials_sunlinsolsuperlumt needs libgomp).
 *
 * Only the macros the public headers read matter to a user of the libraries (precision, index
 * type, counter type, MPI, compiler builtins, deprecation and export attributes); the rest are
 * kept for completeness. Profiling, monitoring and logging settings change macros used inside
 * the libraries only, and are left out.
 *
 * daeclear.codegen compiles with -DDC_SUNDIALS_MAJOR/_MINOR/_PATCH and -DDC_INDEX_SIZE, the
 * version and index width it detected in the installed wheel; a disagreement with this file
 * stops the build here (a library built for other headers would corrupt memory). */

#ifndef _SUNDIALS_CONFIG_H
#define _SUNDIALS_CONFIG_H

#include "sundials/sundials_export.h"

/* Indicates that the function will not report an error via last_err,
   a return code. In C++, it is just defined as noexcept. */
#if defined(__cplusplus)
#define SUNDIALS_NOEXCEPT noexcept
#else
#define SUNDIALS_NOEXCEPT
#endif

#ifndef SUNDIALS_DEPRECATED_MSG
#define SUNDIALS_DEPRECATED_MSG(msg) __attribute__((__deprecated__(msg)))
#endif
#ifndef SUNDIALS_DEPRECATED_EXPORT_MSG
#define SUNDIALS_DEPRECATED_EXPORT_MSG(msg) SUNDIALS_EXPORT SUNDIALS_DEPRECATED_MSG(msg)
#endif
#ifndef SUNDIALS_DEPRECATED_NO_EXPORT_MSG
#define SUNDIALS_DEPRECATED_NO_EXPORT_MSG(msg) SUNDIALS_NO_EXPORT SUNDIALS_DEPRECATED_MSG(msg)
#endif

/* ------------------------------------------------------------------
 * SUNDIALS version numbers
 * -----------------------------------------------------------------*/

#define SUNDIALS_VERSION "7.9.0"
#define SUNDIALS_VERSION_MAJOR 7
#define SUNDIALS_VERSION_MINOR 9
#define SUNDIALS_VERSION_PATCH 0
#define SUNDIALS_VERSION_LABEL ""
#define SUNDIALS_GIT_VERSION "312fc0f3684f"

/* ------------------------------------------------------------------
 * SUNDIALS build information
 * -----------------------------------------------------------------*/

#if defined(__GNUC__) || defined(__clang__)
#define SUNDIALS_C_COMPILER_HAS_BUILTIN_EXPECT
#define SUNDIALS_C_COMPILER_HAS_ATTRIBUTE_UNUSED
#endif

/* precision: sunrealtype is double */
#define SUNDIALS_DOUBLE_PRECISION 1

/* index type: sunindextype is a 32-bit integer */
#define SUNDIALS_INT32_T 1
#define SUNDIALS_INDEX_TYPE int32_t

/* counters (IDAGetNum* and friends) */
#define SUNDIALS_COUNTER_TYPE long int

/* no MPI */
#define SUNDIALS_MPI_ENABLED 0

/* SuperLU_MT threading */
#define SUNDIALS_SUPERLUMT_THREAD_TYPE "OPENMP"

/* modules built (a library of each is in the wheel) */
#define SUNDIALS_CVODE 1
#define SUNDIALS_IDA 1
#define SUNDIALS_NVECTOR_SERIAL 1
#define SUNDIALS_SUNMATRIX_BAND 1
#define SUNDIALS_SUNMATRIX_DENSE 1
#define SUNDIALS_SUNMATRIX_SPARSE 1
#define SUNDIALS_SUNLINSOL_BAND 1
#define SUNDIALS_SUNLINSOL_DENSE 1
#define SUNDIALS_SUNLINSOL_LAPACKBAND 1
#define SUNDIALS_SUNLINSOL_LAPACKDENSE 1
#define SUNDIALS_SUNLINSOL_SPBCGS 1
#define SUNDIALS_SUNLINSOL_SPGMR 1
#define SUNDIALS_SUNLINSOL_SPTFQMR 1
#define SUNDIALS_SUNLINSOL_SUPERLUMT 1

/* ------------------------------------------------------------------
 * daeclear: the build must be for the SUNDIALS this file describes
 * -----------------------------------------------------------------*/

#if defined(DC_SUNDIALS_MAJOR) || defined(DC_SUNDIALS_MINOR) || defined(DC_SUNDIALS_PATCH) || \
  defined(DC_INDEX_SIZE)
#if !defined(DC_SUNDIALS_MAJOR) || !defined(DC_SUNDIALS_MINOR) || !defined(DC_SUNDIALS_PATCH) || \
  !defined(DC_INDEX_SIZE)
#error "daeclear: give all of -DDC_SUNDIALS_MAJOR, _MINOR, _PATCH and -DDC_INDEX_SIZE, or none"
#endif
#if DC_SUNDIALS_MAJOR != SUNDIALS_VERSION_MAJOR || DC_SUNDIALS_MINOR != SUNDIALS_VERSION_MINOR || \
  DC_SUNDIALS_PATCH != SUNDIALS_VERSION_PATCH
#error "daeclear: the installed SUNDIALS libraries (-DDC_SUNDIALS_MAJOR/_MINOR/_PATCH) are not version 7.9.0, the version of the vendored headers in daeclear/csrc/sundials"
#endif
#if DC_INDEX_SIZE != 32
#error "daeclear: the installed SUNDIALS libraries (-DDC_INDEX_SIZE) do not use the 32-bit sunindextype of the vendored sundials_config.h"
#endif
#endif

#endif /* _SUNDIALS_CONFIG_H */
