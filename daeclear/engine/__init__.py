"""The compiled path: C generated from the DAE and its on-disk cache (codegen), the ctypes session over
SUNDIALS IDA (ida_session), and csrc/ (hand-written drivers, vendored SUNDIALS headers).
"""
