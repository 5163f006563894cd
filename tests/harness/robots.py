"""Robots shared by several tests."""

import numpy as np

import softrod

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


# Tapered soft arms with tendons at random angles, curled by known tensions (0.1 to 5 turns):
# from rest the iteration stops at a local minimum of the distance beyond a fold of the tip's
# map (TargetUnreachableError for a reachable target).
ARM = """
name = "curl"
[rod]
length = {length}
[rod.section]
type = "tapered"
base_radius = {base}
tip_radius = {tip}
[rod.material]
type = "linear"
youngs_modulus = {modulus}
poisson_ratio = 0.5
"""

TENDON = """
[[tendons]]
offset = [{x}, {y}]
"""

CURLED = {
    # three tendons, the third pulled: 2.1 turns
    "three": (
        dict(length=0.49888397431568443, base=0.00986584737143361, tip=0.007694171021347452,
             modulus=1999486.8512695632),
        [(-0.0023216761699450953, -0.0057007009300247035),
         (0.006097789909751517, 0.0008397199224789374),
         (-0.003776113739806415, 0.004860981007545767)],
        [0.0, 0.0, 22.58673650678362],
    ),
    # two antagonistic tendons, one pulled
    "antagonistic": (
        dict(length=0.3937934287154917, base=0.00797800014592825, tip=0.0075985806648492344,
             modulus=169771.68792078985),
        [(0.0054577091041494484, -0.002676939545717354),
         (-0.00545770910414945, 0.00267693954571735)],
        [0.0, 5.650332047526689],
    ),
    # three tendons, two pulled
    "two_pulled": (
        dict(length=0.46547630508295557, base=0.0034568929148790398, tip=0.0030575932388536703,
             modulus=580269.2542351008),
        [(-0.0011179597548135033, 0.002175648614036487),
         (-0.0013251870920572507, -0.00205600585509536),
         (0.0024431468468707543, -0.00011964275894112841)],
        [0.0, 1.0926250404024493, 0.5305078506258559],
    ),
}  # fmt: skip


def curled(name):
    """The robot of CURLED[name], its known tensions (N) and the tip they put it at (m)."""
    rod, offsets, truth = CURLED[name]
    text = ARM.format(**rod) + "".join(TENDON.format(x=x, y=y) for x, y in offsets)
    robot = softrod.Robot.from_toml(text)
    truth = np.array(truth)
    return robot, truth, robot.solve(truth).tip_position
