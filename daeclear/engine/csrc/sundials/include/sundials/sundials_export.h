/* sundials_export.h -- written by daeclear, not part of the SUNDIALS release.
 *
 * SUNDIALS' CMake build generates this file (GenerateExportHeader) next to sundials_config.h.
 * This is the output for a GCC/Clang shared-library build as consumed by a user of the
 * libraries (the scikit-sundae wheel's case): exported symbols have default visibility. */

#ifndef SUNDIALS_EXPORT_H
#define SUNDIALS_EXPORT_H

#ifdef SUNDIALS_STATIC_DEFINE
#define SUNDIALS_EXPORT
#define SUNDIALS_NO_EXPORT
#else
#ifndef SUNDIALS_EXPORT
#define SUNDIALS_EXPORT __attribute__((visibility("default")))
#endif
#ifndef SUNDIALS_NO_EXPORT
#define SUNDIALS_NO_EXPORT __attribute__((visibility("hidden")))
#endif
#endif

#ifndef SUNDIALS_DEPRECATED_ATTRIBUTE
#define SUNDIALS_DEPRECATED_ATTRIBUTE __attribute__((__deprecated__))
#endif
#ifndef SUNDIALS_DEPRECATED_ATTRIBUTE_EXPORT
#define SUNDIALS_DEPRECATED_ATTRIBUTE_EXPORT SUNDIALS_EXPORT SUNDIALS_DEPRECATED_ATTRIBUTE
#endif
#ifndef SUNDIALS_DEPRECATED_ATTRIBUTE_NO_EXPORT
#define SUNDIALS_DEPRECATED_ATTRIBUTE_NO_EXPORT SUNDIALS_NO_EXPORT SUNDIALS_DEPRECATED_ATTRIBUTE
#endif

#endif /* SUNDIALS_EXPORT_H */
