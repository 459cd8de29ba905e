"""Scene-file texts shared by the tests: a one-link pendulum hanging from a ground pin."""

#: The link and its pin, without a [scene] table (tests add tables around it).
PENDULUM_LINK = """
[[body]]
name = "link"
mass = 1.0
inertia = 0.01
position = [0.5, 0.0]

[[revolute]]
name = "A"
body_i = "ground"
body_j = "link"
at = [0.0, 0.0]
"""

#: A complete scene file (no [simulate] table).
PENDULUM = """
[scene]
name = "pendulum"
gravity = [0.0, -9.81]
""" + PENDULUM_LINK
