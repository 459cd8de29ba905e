/*
 * sundials_min.h -- the few SUNDIALS 7.x declarations that daeclear's IDA driver needs.
 *
 * The scikit-sundae wheel ships the SUNDIALS shared libraries (scikit_sundae.libs/) but not
 * their headers, so the prototypes are restated here. Every line was checked against the
 * SUNDIALS 7.x public headers (include/ida/ida.h, include/ida/ida_ls.h,
 * include/sundials/sundials_types.h, sundials_context.h, sundials_nvector.h,
 * sundials_matrix.h, sundials_linearsolver.h, sundials_version.h,
 * include/nvector/nvector_serial.h, include/sunmatrix/sunmatrix_dense.h,
 * include/sunmatrix/sunmatrix_sparse.h, include/sunlinsol/sunlinsol_dense.h,
 * include/sunlinsol/sunlinsol_superlumt.h) and against the build configuration of the wheel:
 *
 *   sunrealtype  = double
 *   sunindextype = int32_t or int64_t: NOT fixed here, daeclear.codegen reads it from the wheel
 *                  (sksundae/c_config.pxi, cross-checked on the loaded libraries) and passes
 *                  -DDC_INDEX_SIZE=32|64
 *   SUNComm      = int        (no MPI)
 *   sunbooleantype = int, SUNErrCode = int
 *   counters of IDAGetNum* = long int
 *
 * daeclear.codegen also passes the version of the wheel's SUNDIALS (-DDC_SUNDIALS_MAJOR, _MINOR,
 * _PATCH); this file refuses any major version but 7, for which it was written. A wrong
 * prototype or index width here is silent memory corruption: change nothing without re-checking
 * the headers of the exact SUNDIALS version the wheel ships (SUNDIALSGetVersion).
 */
#ifndef DAECLEAR_SUNDIALS_MIN_H
#define DAECLEAR_SUNDIALS_MIN_H

#include <stdint.h>

#if !defined(DC_SUNDIALS_MAJOR) || !defined(DC_SUNDIALS_MINOR) || !defined(DC_SUNDIALS_PATCH) || \
    !defined(DC_INDEX_SIZE)
#error "compile with -DDC_SUNDIALS_MAJOR/_MINOR/_PATCH and -DDC_INDEX_SIZE as daeclear.codegen does"
#endif
#if DC_SUNDIALS_MAJOR != 7
#error "sundials_min.h declares the SUNDIALS 7.x API; the wheel's SUNDIALS has another major version"
#endif

typedef double sunrealtype;
#if DC_INDEX_SIZE == 32
typedef int32_t sunindextype;
#elif DC_INDEX_SIZE == 64
typedef int64_t sunindextype;
#else
#error "DC_INDEX_SIZE must be 32 or 64 (the width of the wheel's sunindextype)"
#endif
typedef int sunbooleantype;
typedef int SUNComm;
typedef int SUNErrCode;

#define SUN_COMM_NULL 0

typedef struct SUNContext_* SUNContext;
typedef struct _generic_N_Vector* N_Vector;
typedef struct _generic_SUNMatrix* SUNMatrix;
typedef struct _generic_SUNLinearSolver* SUNLinearSolver;

/* sundials_types.h: error handler function type */
typedef void (*SUNErrHandlerFn)(int line, const char* func, const char* file, const char* msg,
                                SUNErrCode err_code, void* err_user_data, SUNContext sunctx);

/* sundials_context.h */
SUNErrCode SUNContext_Create(SUNComm comm, SUNContext* sunctx_out);
SUNErrCode SUNContext_Free(SUNContext* ctx);
SUNErrCode SUNContext_ClearErrHandlers(SUNContext sunctx);
SUNErrCode SUNContext_PushErrHandler(SUNContext sunctx, SUNErrHandlerFn err_fn, void* err_user_data);

/* sundials_version.h */
SUNErrCode SUNDIALSGetVersion(char* version, int len);

/* sundials_nvector.h, nvector_serial.h */
N_Vector N_VNew_Serial(sunindextype vec_length, SUNContext sunctx);
sunrealtype* N_VGetArrayPointer(N_Vector v);
void N_VDestroy(N_Vector v);

/* sundials_matrix.h, sunmatrix_dense.h (column-major data) */
SUNMatrix SUNDenseMatrix(sunindextype M, sunindextype N, SUNContext sunctx);
sunrealtype* SUNDenseMatrix_Data(SUNMatrix A);
void SUNMatDestroy(SUNMatrix A);

/* sunmatrix_sparse.h: compressed sparse column (CSC_MAT) storage; the index arrays are
 * sunindextype, and SUNMatZero clears them too (so a Jacobian callback rewrites the pattern) */
#define CSC_MAT 0
SUNMatrix SUNSparseMatrix(sunindextype M, sunindextype N, sunindextype NNZ, int sparsetype,
                          SUNContext sunctx);
sunrealtype* SUNSparseMatrix_Data(SUNMatrix A);
sunindextype* SUNSparseMatrix_IndexValues(SUNMatrix A);
sunindextype* SUNSparseMatrix_IndexPointers(SUNMatrix A);

/* sundials_linearsolver.h, sunlinsol_dense.h, sunlinsol_superlumt.h */
SUNLinearSolver SUNLinSol_Dense(N_Vector y, SUNMatrix A, SUNContext sunctx);
SUNLinearSolver SUNLinSol_SuperLUMT(N_Vector y, SUNMatrix A, int num_threads, SUNContext sunctx);
int SUNLinSolGetType_SuperLUMT(SUNLinearSolver S); /* returns the enum SUNLinearSolver_Type */
int SUNLinSolGetID_SuperLUMT(SUNLinearSolver S);   /* returns the enum SUNLinearSolver_ID */
SUNErrCode SUNLinSolInitialize_SuperLUMT(SUNLinearSolver S);
SUNErrCode SUNLinSolFree_SuperLUMT(SUNLinearSolver S);
int SUNLinSolSetup(SUNLinearSolver S, SUNMatrix A);
SUNErrCode SUNLinSolFree(SUNLinearSolver S);

/* A SUNLinearSolver starts with its content pointer, followed (SUNDIALS 7.0-7.5 headers) by the
 * ops table pointer, or (the wheel's 7.9, observed) by one more pointer and then the ops table;
 * the table's own layout also changed within 7.x (setoptions was inserted). The driver therefore
 * assumes no position: it finds both by their values (find_ops in ida_driver.c). The functions
 * above whose enum results are declared int are only compared by address. An op is any
 * function pointer: */
typedef void (*dc_sun_op)(void);

/* ida.h */
#define IDA_NORMAL 1
#define IDA_ONE_STEP 2

#define IDA_SUCCESS 0
#define IDA_TSTOP_RETURN 1
#define IDA_ROOT_RETURN 2
#define IDA_WARNING 99

typedef int (*IDAResFn)(sunrealtype tt, N_Vector yy, N_Vector yp, N_Vector rr, void* user_data);
typedef int (*IDARootFn)(sunrealtype t, N_Vector y, N_Vector yp, sunrealtype* gout, void* user_data);

void* IDACreate(SUNContext sunctx);
int IDAInit(void* ida_mem, IDAResFn res, sunrealtype t0, N_Vector yy0, N_Vector yp0);
int IDAReInit(void* ida_mem, sunrealtype t0, N_Vector yy0, N_Vector yp0);
int IDASVtolerances(void* ida_mem, sunrealtype reltol, N_Vector abstol);
int IDASetUserData(void* ida_mem, void* user_data);
int IDASetMaxOrd(void* ida_mem, int maxord);
int IDASetMaxNumSteps(void* ida_mem, long int mxsteps);
int IDASetMaxStep(void* ida_mem, sunrealtype hmax);
int IDASetStopTime(void* ida_mem, sunrealtype tstop);
int IDASetNonlinConvCoef(void* ida_mem, sunrealtype epcon);
int IDASetInitStep(void* ida_mem, sunrealtype hin);
int IDARootInit(void* ida_mem, int nrtfn, IDARootFn g);
int IDASetRootDirection(void* ida_mem, int* rootdir);
int IDASetNoInactiveRootWarn(void* ida_mem);
int IDASolve(void* ida_mem, sunrealtype tout, sunrealtype* tret, N_Vector yret, N_Vector ypret,
             int itask);
int IDAGetDky(void* ida_mem, sunrealtype t, int k, N_Vector dky);
int IDAGetNumSteps(void* ida_mem, long int* nsteps);
int IDAGetNumResEvals(void* ida_mem, long int* nrevals);
int IDAGetNumLinSolvSetups(void* ida_mem, long int* nlinsetups);
int IDAGetNumErrTestFails(void* ida_mem, long int* netfails);
int IDAGetLastOrder(void* ida_mem, int* klast);
int IDAGetLastStep(void* ida_mem, sunrealtype* hlast);
int IDAGetCurrentTime(void* ida_mem, sunrealtype* tcur);
int IDAGetNumGEvals(void* ida_mem, long int* ngevals);
int IDAGetRootInfo(void* ida_mem, int* rootsfound);
int IDAGetNumNonlinSolvIters(void* ida_mem, long int* nniters);
int IDAGetNumNonlinSolvConvFails(void* ida_mem, long int* nnfails);
char* IDAGetReturnFlagName(long int flag); /* result is malloc'ed: free() it */
void IDAFree(void** ida_mem);

/* ida_ls.h */
typedef int (*IDALsJacFn)(sunrealtype t, sunrealtype c_j, N_Vector y, N_Vector yp, N_Vector r,
                          SUNMatrix Jac, void* user_data, N_Vector tmp1, N_Vector tmp2,
                          N_Vector tmp3);
int IDASetLinearSolver(void* ida_mem, SUNLinearSolver LS, SUNMatrix A);
int IDASetJacFn(void* ida_mem, IDALsJacFn jac);
int IDAGetNumJacEvals(void* ida_mem, long int* njevals);

#endif
