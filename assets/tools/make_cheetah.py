#!/usr/bin/env python3
"""Generates pixelgym's planar cheetah (CheetahRun): assets/cheetah/cheetah.urdf.

Usage: python3 assets/tools/make_cheetah.py        (writes assets/cheetah/cheetah.urdf)

The model is dm_control's cheetah (suite/cheetah.xml) written as a URDF: the same capsules (radius
0.046 m, placed and turned as there), the same joints, ranges, springs, damping and motor gears,
and masses from the capsules' volumes at 1000 kg/m^3, scaled so that the whole cheetah weighs
14 kg (dm_control's settotalmass). The torso moves in the x-z plane through the chain of a slider
along x, a slider along z and a hinge about y on a fixed base, as dm_control's rootx, rootz and
rooty; every leg joint is a hinge about y. Joint positions of 0 are dm_control's qpos0: the torso
at height 0.7 m, level, the legs as drawn.

Joint springs (dm_control's stiffness) are written as <dynamics stiffness="..."/>, which
pixelgym's URDF reader takes as a spring towards position 0 (other URDF readers ignore it).
dm_control's leg joints have an armature of 0.1 kg m^2 (a motor's rotor inertia, added to the
joint's inertia), which Bullet's multibodies lack; it is added to each leg link's moment of
inertia about y instead. That gives each joint the same inertia against its own torque (the
armature is 60-90% of it for the shins and feet), but the added inertia also turns with the
links above: the whole cheetah pitching with its joints still carries 0.6 kg m^2 more than in
dm_control (docs/tasks.md compares the two).
Standard library only; running it again gives an identical file.
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "cheetah", "cheetah.urdf"))

RADIUS = 0.046
DENSITY = 1000.0
TOTAL_MASS = 14.0
TORSO_HEIGHT = 0.7

# Capsules as dm_control gives them, in their body's frame: (name, body, centre (x, z), tilt about
# +y in degrees (0: along +z; dm_control's euler "0 tilt 0"), half-length of the cylinder). The
# torso capsule is "fromto -.5 0 0 .5 0 0": along x, centred, half-length 0.5.
CAPSULES = [
    ("torso", "torso", (0.0, 0.0), 90.0, 0.5),
    ("head", "torso", (0.6, 0.1), 50.0, 0.15),
    ("bthigh", "bthigh", (0.1, -0.13), -218.0, 0.145),
    ("bshin", "bshin", (-0.14, -0.07), -116.0, 0.15),
    ("bfoot", "bfoot", (0.03, -0.097), -15.0, 0.094),
    ("fthigh", "fthigh", (-0.07, -0.12), 30.0, 0.133),
    ("fshin", "fshin", (0.065, -0.09), -34.0, 0.106),
    ("ffoot", "ffoot", (0.045, -0.07), -34.0, 0.07),
]

# Leg joints: (joint = child body, parent, origin in the parent's frame (x, z), range in degrees,
# stiffness N m/rad, damping N m s/rad, motor gear N m). dm_control writes fthigh's upper limit as
# ".40" degrees (not 40): kept.
LEGS = [
    ("bthigh", "torso", (-0.5, 0.0), (-30.0, 60.0), 240.0, 6.0, 120.0),
    ("bshin", "bthigh", (0.16, -0.25), (-50.0, 50.0), 180.0, 4.5, 90.0),
    ("bfoot", "bshin", (-0.28, -0.14), (-230.0, 50.0), 120.0, 3.0, 60.0),
    ("fthigh", "torso", (0.5, 0.0), (-57.0, 0.40), 180.0, 4.5, 90.0),
    ("fshin", "fthigh", (-0.14, -0.24), (-70.0, 50.0), 120.0, 3.0, 60.0),
    ("ffoot", "fshin", (0.13, -0.18), (-28.0, 28.0), 60.0, 1.5, 30.0),
]

# dm_control's armature of every leg joint, kg m^2 (see the docstring).
ARMATURE = 0.1

# The two links between the fixed base and the torso that carry the sliders. They need some
# mass for the simulator; 1 g each is 0.007% of the cheetah.
SLIDER_MASS = 0.001
SLIDER_INERTIA = 1e-6

COLOUR = (0.7, 0.5, 0.3)  # dm_control's "self" material


def capsule_volume(half_length):
    return math.pi * RADIUS**2 * 2 * half_length + 4.0 / 3.0 * math.pi * RADIUS**3


def capsule_inertia(mass, half_length):
    """Moments about the centre: (about the capsule's axis, about a perpendicular axis)."""
    cylinder = math.pi * RADIUS**2 * 2 * half_length
    sphere = 4.0 / 3.0 * math.pi * RADIUS**3
    m_cyl = mass * cylinder / (cylinder + sphere)
    m_hemi = mass * sphere / (cylinder + sphere) / 2
    length = 2 * half_length
    axial = m_cyl * RADIUS**2 / 2 + 2 * m_hemi * 2 * RADIUS**2 / 5
    perpendicular = m_cyl * (RADIUS**2 / 4 + length**2 / 12) + 2 * m_hemi * (
        2 * RADIUS**2 / 5 + length**2 / 4 + 3 * length * RADIUS / 8)
    return axial, perpendicular


def rotation_y(degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]


def link_inertial(capsules, scale):
    """Mass, centre of mass (3) and inertia (3x3 about it, link axes) of a link's capsules."""
    parts = []
    for _, _, (x, z), tilt, half in capsules:
        mass = DENSITY * capsule_volume(half) * scale
        axial, perp = capsule_inertia(mass, half)
        r = rotation_y(tilt)
        local = [[perp, 0, 0], [0, perp, 0], [0, 0, axial]]  # capsule axis = local z
        inertia = [[sum(r[i][k] * local[k][l] * r[j][l] for k in range(3) for l in range(3))
                    for j in range(3)] for i in range(3)]
        parts.append((mass, (x, 0.0, z), inertia))
    total = sum(p[0] for p in parts)
    com = tuple(sum(p[0] * p[1][i] for p in parts) / total for i in range(3))
    inertia = [[0.0] * 3 for _ in range(3)]
    for mass, centre, own in parts:
        d = [centre[i] - com[i] for i in range(3)]
        d2 = sum(v * v for v in d)
        for i in range(3):
            for j in range(3):
                inertia[i][j] += own[i][j] + mass * ((d2 if i == j else 0.0) - d[i] * d[j])
    return total, com, inertia


def fmt(value):
    text = "%.6g" % value
    return "0" if text in ("-0", "0") else text


def inertial_xml(mass, com, inertia):
    return ("    <inertial>\n"
            "      <origin xyz=\"%s %s %s\"/>\n"
            "      <mass value=\"%s\"/>\n"
            "      <inertia ixx=\"%s\" ixy=\"%s\" ixz=\"%s\" iyy=\"%s\" iyz=\"%s\" izz=\"%s\"/>\n"
            "    </inertial>\n") % (fmt(com[0]), fmt(com[1]), fmt(com[2]), fmt(mass),
                                    fmt(inertia[0][0]), fmt(inertia[0][1]), fmt(inertia[0][2]),
                                    fmt(inertia[1][1]), fmt(inertia[1][2]), fmt(inertia[2][2]))


def capsule_xml(kind, x, z, tilt, half):
    return ("    <%s>\n"
            "      <origin xyz=\"%s 0 %s\" rpy=\"0 %s 0\"/>\n"
            "      <geometry><capsule radius=\"%s\" length=\"%s\"/></geometry>\n"
            "%s"
            "    </%s>\n") % (kind, fmt(x), fmt(z), fmt(math.radians(tilt)), fmt(RADIUS),
                             fmt(2 * half),
                             "      <material name=\"self\"/>\n" if kind == "visual" else "",
                             kind)


def main():
    scale = TOTAL_MASS / sum(DENSITY * capsule_volume(c[4]) for c in CAPSULES)
    bodies = ["torso"] + [leg[0] for leg in LEGS]
    out = []
    out.append("<?xml version=\"1.0\"?>\n")
    out.append("<!-- Generated by assets/tools/make_cheetah.py: edit that, not this. dm_control's "
               "planar cheetah\n     (suite/cheetah.xml) as a URDF; the tool's docstring says "
               "what is kept and how. -->\n")
    out.append("<robot name=\"cheetah\">\n")
    out.append("  <material name=\"self\"><color rgba=\"%s %s %s 1\"/></material>\n" % COLOUR)
    out.append("  <link name=\"base\"/>\n")
    for name in ("root_x", "root_z"):
        out.append("  <link name=\"%s\">\n" % name)
        out.append(inertial_xml(SLIDER_MASS, (0, 0, 0), [[SLIDER_INERTIA, 0, 0],
                                                          [0, SLIDER_INERTIA, 0],
                                                          [0, 0, SLIDER_INERTIA]]))
        out.append("  </link>\n")
    total_mass = 0.0
    for body in bodies:
        capsules = [c for c in CAPSULES if c[1] == body]
        mass, com, inertia = link_inertial(capsules, scale)
        if body != "torso":
            inertia[1][1] += ARMATURE
        total_mass += mass
        out.append("  <link name=\"%s\">\n" % body)
        out.append(inertial_xml(mass, com, inertia))
        for kind in ("visual", "collision"):
            for _, _, (x, z), tilt, half in capsules:
                out.append(capsule_xml(kind, x, z, tilt, half))
        out.append("  </link>\n")
    assert abs(total_mass - TOTAL_MASS) < 1e-9
    out.append("  <joint name=\"rootx\" type=\"prismatic\">\n"
               "    <parent link=\"base\"/><child link=\"root_x\"/>\n"
               "    <origin xyz=\"0 0 %s\"/><axis xyz=\"1 0 0\"/>\n"
               "    <limit lower=\"-1000\" upper=\"1000\" effort=\"0\" velocity=\"100\"/>\n"
               "  </joint>\n" % fmt(TORSO_HEIGHT))
    out.append("  <joint name=\"rootz\" type=\"prismatic\">\n"
               "    <parent link=\"root_x\"/><child link=\"root_z\"/>\n"
               "    <axis xyz=\"0 0 1\"/>\n"
               "    <limit lower=\"-1000\" upper=\"1000\" effort=\"0\" velocity=\"100\"/>\n"
               "  </joint>\n")
    out.append("  <joint name=\"rooty\" type=\"continuous\">\n"
               "    <parent link=\"root_z\"/><child link=\"torso\"/>\n"
               "    <axis xyz=\"0 1 0\"/>\n"
               "    <limit effort=\"0\" velocity=\"100\"/>\n"
               "  </joint>\n")
    for name, parent, (x, z), (lower, upper), stiffness, damping, gear in LEGS:
        out.append("  <joint name=\"%s\" type=\"revolute\">\n"
                   "    <parent link=\"%s\"/><child link=\"%s\"/>\n"
                   "    <origin xyz=\"%s 0 %s\"/><axis xyz=\"0 1 0\"/>\n"
                   "    <limit lower=\"%s\" upper=\"%s\" effort=\"%s\" velocity=\"100\"/>\n"
                   "    <dynamics damping=\"%s\" stiffness=\"%s\"/>\n"
                   "  </joint>\n" % (name, parent, name, fmt(x), fmt(z),
                                     fmt(math.radians(lower)), fmt(math.radians(upper)),
                                     fmt(gear), fmt(damping), fmt(stiffness)))
    out.append("</robot>\n")
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        f.write("".join(out))


if __name__ == "__main__":
    main()
