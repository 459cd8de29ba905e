"""Scenes and what they are made of: bodies, joints, drivers, loads, readings, the mechanism library and
scene files. Nothing here builds equations; :mod:`daeclear.assembly` turns a scene into a DAE.
"""
