"""The compiled path: C generated from the DAE (codegen), compiled and cached (build) against the
wheel's SUNDIALS (sundials), loaded with ctypes (library) and kept for a process by its owner
(compiled); the IDA session (ida_session: open_session, with session_base, the compiled c_session and
the scikit-sundae python_session); the cubic Hermite interpolant (hermite); and csrc/ (hand-written
drivers, vendored SUNDIALS headers).
"""
