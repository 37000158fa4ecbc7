"""Shared by the generators of dm_control's planar models (make_cheetah.py, make_walker.py,
make_finger.py): capsule and cylinder masses and inertias, and the URDF text of links and
joints. Standard library only."""
import math
import os

DENSITY = 1000.0  # MuJoCo's default, kg/m^3


class Capsule:
    """A capsule in its link's frame: centre (x, z), turned about +y by `tilt` degrees from
    +z (dm_control's euler "0 tilt 0"), radius and half-length of the cylinder, m. `material`
    (None: the link's) colours it; `collides` False makes it drawn only (dm_control's
    contype="0" conaffinity="0")."""

    def __init__(self, centre, tilt, radius, half_length, material=None, collides=True):
        self.centre, self.tilt, self.radius, self.half = centre, tilt, radius, half_length
        self.material, self.collides = material, collides

    def rpy(self):
        return (0.0, math.radians(self.tilt), 0.0)

    def geometry_xml(self):
        return "<capsule radius=\"%s\" length=\"%s\"/>" % (fmt(self.radius), fmt(2 * self.half))

    def volume(self):
        r = self.radius
        return math.pi * r**2 * 2 * self.half + 4.0 / 3.0 * math.pi * r**3

    def rotation(self):
        return rotation_y(self.tilt)

    def moments(self, mass):
        """(about its axis, about a perpendicular axis through its centre), kg m^2."""
        r, length = self.radius, 2 * self.half
        cylinder = math.pi * r**2 * length
        sphere = 4.0 / 3.0 * math.pi * r**3
        m_cyl = mass * cylinder / (cylinder + sphere)
        m_hemi = mass * sphere / (cylinder + sphere) / 2
        axial = m_cyl * r**2 / 2 + 2 * m_hemi * 2 * r**2 / 5
        perpendicular = m_cyl * (r**2 / 4 + length**2 / 12) + 2 * m_hemi * (
            2 * r**2 / 5 + length**2 / 4 + 3 * length * r / 8)
        return axial, perpendicular


class CylinderY(Capsule):
    """A cylinder along y in its link's frame (dm_control's fromto "0 -h 0 0 h 0"): centre
    (x, z), radius and half-length, m."""

    def __init__(self, centre, radius, half_length, material=None, collides=True):
        super().__init__(centre, 0.0, radius, half_length, material, collides)

    def rpy(self):
        return (math.pi / 2, 0.0, 0.0)  # turns the URDF cylinder's z axis onto -y

    def geometry_xml(self):
        return "<cylinder radius=\"%s\" length=\"%s\"/>" % (fmt(self.radius), fmt(2 * self.half))

    def volume(self):
        return math.pi * self.radius**2 * 2 * self.half

    def rotation(self):
        return [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]

    def moments(self, mass):
        r, length = self.radius, 2 * self.half
        return mass * r**2 / 2, mass * (r**2 / 4 + length**2 / 12)


class Sphere(Capsule):
    """A sphere in its link's frame: centre (x, z) and radius, m."""

    def __init__(self, centre, radius, material=None, collides=True):
        super().__init__(centre, 0.0, radius, 0.0, material, collides)

    def geometry_xml(self):
        return "<sphere radius=\"%s\"/>" % fmt(self.radius)

    def volume(self):
        return 4.0 / 3.0 * math.pi * self.radius**3

    def moments(self, mass):
        return 2 * mass * self.radius**2 / 5, 2 * mass * self.radius**2 / 5


def segment(start, end, radius, material=None):
    """The capsule of dm_control's fromto: from (x, z) to (x, z), in the link's frame."""
    dx, dz = end[0] - start[0], end[1] - start[1]
    centre = ((start[0] + end[0]) / 2, (start[1] + end[1]) / 2)
    return Capsule(centre, math.degrees(math.atan2(dx, dz)), radius, math.hypot(dx, dz) / 2,
                   material)


def rotation_y(degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]


def link_inertial(capsules, scale=1.0, armature=0.0):
    """Mass, centre of mass (3) and inertia (3x3 about it, link axes) of a link's capsules at
    DENSITY times `scale`; `armature` is added to the moment about y (see the generators)."""
    parts = []
    for capsule in capsules:
        mass = DENSITY * capsule.volume() * scale
        axial, perp = capsule.moments(mass)
        r = capsule.rotation()
        local = [[perp, 0, 0], [0, perp, 0], [0, 0, axial]]  # the capsule's axis is local z
        inertia = [[sum(r[i][k] * local[k][l] * r[j][l] for k in range(3) for l in range(3))
                    for j in range(3)] for i in range(3)]
        parts.append((mass, (capsule.centre[0], 0.0, capsule.centre[1]), inertia))
    total = sum(p[0] for p in parts)
    com = tuple(sum(p[0] * p[1][i] for p in parts) / total for i in range(3))
    inertia = [[0.0] * 3 for _ in range(3)]
    for mass, centre, own in parts:
        d = [centre[i] - com[i] for i in range(3)]
        d2 = sum(v * v for v in d)
        for i in range(3):
            for j in range(3):
                inertia[i][j] += own[i][j] + mass * ((d2 if i == j else 0.0) - d[i] * d[j])
    inertia[1][1] += armature
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


def link_xml(name, capsules, mass, com, inertia, material="self"):
    """A link with its inertial, each shape as a visual and each that collides as a
    collision."""
    out = ["  <link name=\"%s\">\n" % name, inertial_xml(mass, com, inertia)]
    for kind in ("visual", "collision"):
        for c in capsules:
            if kind == "collision" and not c.collides:
                continue
            rpy = c.rpy()
            out.append("    <%s>\n"
                       "      <origin xyz=\"%s 0 %s\" rpy=\"%s %s %s\"/>\n"
                       "      <geometry>%s</geometry>\n"
                       "%s"
                       "    </%s>\n" % (kind, fmt(c.centre[0]), fmt(c.centre[1]), fmt(rpy[0]),
                                       fmt(rpy[1]), fmt(rpy[2]), c.geometry_xml(),
                                       "      <material name=\"%s\"/>\n" % (c.material or material)
                                       if kind == "visual" else "", kind))
    out.append("  </link>\n")
    return "".join(out)


def slider_links(names, mass=0.001, inertia=1e-6):
    """The links between a fixed base and the body that carry the root sliders. They need some
    mass for the simulator; 1 g each."""
    out = []
    for name in names:
        out.append("  <link name=\"%s\">\n" % name)
        out.append(inertial_xml(mass, (0, 0, 0), [[inertia, 0, 0], [0, inertia, 0],
                                                  [0, 0, inertia]]))
        out.append("  </link>\n")
    return "".join(out)


def root_joint_xml(name, kind, parent, child, axis, origin=(0.0, 0.0, 0.0)):
    """An unlimited root joint: a slider ("prismatic", limits of 1000 m) or a hinge
    ("continuous")."""
    limit = ("<limit lower=\"-1000\" upper=\"1000\" effort=\"0\" velocity=\"100\"/>"
             if kind == "prismatic" else "<limit effort=\"0\" velocity=\"100\"/>")
    return ("  <joint name=\"%s\" type=\"%s\">\n"
            "    <parent link=\"%s\"/><child link=\"%s\"/>\n"
            "    <origin xyz=\"%s %s %s\"/><axis xyz=\"%s %s %s\"/>\n"
            "    %s\n"
            "  </joint>\n") % (name, kind, parent, child, fmt(origin[0]), fmt(origin[1]),
                               fmt(origin[2]), fmt(axis[0]), fmt(axis[1]), fmt(axis[2]), limit)


def hinge_xml(name, parent, child, origin, axis, limits_deg, gear, damping, stiffness=0.0,
              friction=0.0, rpy=(0.0, 0.0, 0.0)):
    """A hinge with a motor of `gear` N m (the URDF's effort; 0: none), damping and, when not 0,
    dry friction and a spring (pixelgym's <dynamics stiffness>). `limits_deg` None makes it
    unlimited ("continuous"); `rpy` turns the joint frame in the parent's."""
    dynamics = "damping=\"%s\"" % fmt(damping)
    if friction:
        dynamics += " friction=\"%s\"" % fmt(friction)
    if stiffness:
        dynamics += " stiffness=\"%s\"" % fmt(stiffness)
    if limits_deg is None:
        kind, limit = "continuous", "<limit effort=\"%s\" velocity=\"100\"/>" % fmt(gear)
    else:
        kind = "revolute"
        limit = "<limit lower=\"%s\" upper=\"%s\" effort=\"%s\" velocity=\"100\"/>" % (
            fmt(math.radians(limits_deg[0])), fmt(math.radians(limits_deg[1])), fmt(gear))
    turn = "" if not any(rpy) else " rpy=\"%s %s %s\"" % (fmt(rpy[0]), fmt(rpy[1]), fmt(rpy[2]))
    return ("  <joint name=\"%s\" type=\"%s\">\n"
            "    <parent link=\"%s\"/><child link=\"%s\"/>\n"
            "    <origin xyz=\"%s %s %s\"%s/><axis xyz=\"%s %s %s\"/>\n"
            "    %s\n"
            "    <dynamics %s/>\n"
            "  </joint>\n") % (name, kind, parent, child, fmt(origin[0]), fmt(origin[1]),
                               fmt(origin[2]), turn, fmt(axis[0]), fmt(axis[1]), fmt(axis[2]),
                               limit, dynamics)


def slider_xml(name, parent, child, origin, axis, gear, damping, stiffness=0.0):
    """An unlimited slider (limits of 1000 m) with a motor of `gear` N (the URDF's effort; 0:
    none), damping and, when not 0, a spring (pixelgym's <dynamics stiffness>)."""
    dynamics = "damping=\"%s\"" % fmt(damping)
    if stiffness:
        dynamics += " stiffness=\"%s\"" % fmt(stiffness)
    return ("  <joint name=\"%s\" type=\"prismatic\">\n"
            "    <parent link=\"%s\"/><child link=\"%s\"/>\n"
            "    <origin xyz=\"%s %s %s\"/><axis xyz=\"%s %s %s\"/>\n"
            "    <limit lower=\"-1000\" upper=\"1000\" effort=\"%s\" velocity=\"100\"/>\n"
            "    <dynamics %s/>\n"
            "  </joint>\n") % (name, parent, child, fmt(origin[0]), fmt(origin[1]),
                               fmt(origin[2]), fmt(axis[0]), fmt(axis[1]), fmt(axis[2]),
                               fmt(gear), dynamics)


def urdf_start(robot, tool, source, materials):
    """The opening of a generated URDF: the note naming the generator, the robot element and the
    materials {name: (r, g, b)}."""
    out = ["<?xml version=\"1.0\"?>\n",
           "<!-- Generated by assets/tools/%s: edit that, not this. dm_control's %s\n"
           "     (suite/%s) as a URDF; the tool's docstring says what is kept and how. -->\n"
           % (tool, robot, source),
           "<robot name=\"%s\">\n" % robot]
    for name, rgb in materials.items():
        out.append("  <material name=\"%s\"><color rgba=\"%s %s %s 1\"/></material>\n"
                   % ((name,) + tuple(rgb)))
    return out


def write_urdf(path, parts):
    """Closes the robot element and writes the file."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("".join(parts) + "</robot>\n")
