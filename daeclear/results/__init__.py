"""A run's data: :class:`~daeclear.results.result.Result`, its HDF5 files, and safe writes of output
files (outputs).
"""
