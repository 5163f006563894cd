"""Robots shared by several tests."""

# A tapered silicone arm under gravity (0.25 m, radius 6 to 4 mm, 2 MPa), three tendons at
# 120°, the second ending half-way: pulling all three compresses the rod, so a tip is reached
# along a near-flat valley of actuations (co-contraction), and it stands near its self-weight
# buckling load.
TRI_TENDON = """
name = "tri-tendon"
[rod]
length = 0.25
density = 1100.0
[rod.section]
type = "tapered"
base_radius = 0.006
tip_radius = 0.004
[rod.material]
type = "linear"
youngs_modulus = 2.0e6
poisson_ratio = 0.49
[[tendons]]
distance = 0.004
angle_deg = 0.0
[[tendons]]
distance = 0.004
angle_deg = 120.0
end = 0.125
[[tendons]]
distance = 0.004
angle_deg = 240.0
[loads]
gravity = [0.0, 0.0, -9.81]
"""
