"""Studies over many runs: accuracy (work-precision, energy balance), motion analysis, the stability
suite, parameter sweeps and response metrics.
"""
