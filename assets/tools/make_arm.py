#!/usr/bin/env python3
"""Generates pixelgym's 7-DOF arm: its meshes (OBJ visuals, STL collision hulls, a Collada
pedestal) and its URDF, with masses and inertias computed from the same dimensions.

Usage: python3 assets/tools/make_arm.py            (writes into assets/arm/)

Standard library only. The arm stands upright at zero pose; joints alternate z (twist) and
y (bend) axes like common 7-DOF research arms. Running it again gives identical files.
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "arm"))
MESHES = os.path.join(OUT, "meshes")

# name, axis of the joint that moves this link, length to the next joint (m), radius (m),
# mass (kg), lower/upper limit (rad), effort (N m)
LINKS = [
    ("link1", "z", 0.16, 0.070, 4.0, -2.96, 2.96, 120.0),
    ("link2", "y", 0.22, 0.065, 3.5, -2.09, 2.09, 120.0),
    ("link3", "z", 0.20, 0.060, 3.0, -2.96, 2.96, 70.0),
    ("link4", "y", 0.20, 0.055, 2.5, -2.09, 2.09, 70.0),
    ("link5", "z", 0.18, 0.050, 2.0, -2.96, 2.96, 40.0),
    ("link6", "y", 0.08, 0.045, 1.2, -2.09, 2.09, 20.0),
    ("link7", "z", 0.06, 0.040, 0.6, -3.05, 3.05, 10.0),
]
PEDESTAL_HEIGHT = 0.16
PEDESTAL_RADIUS = 0.11
SEGMENTS = 32          # around each visual surface
CAP_RINGS = 8          # per hemisphere of a visual capsule
HULL_SEGMENTS = 12     # coarser collision hulls

SHELL = (0.92, 0.92, 0.9)
ACCENT = (0.95, 0.5, 0.1)
DARK = (0.2, 0.2, 0.22)


def capsule(radius, length, segments, cap_rings, z0=0.0):
    """Vertices, normals and triangles of a capsule along z from z0 to z0 + length (the
    hemispheres are inside that span: the cylinder part is length - 2 radius long)."""
    straight = max(length - 2 * radius, 0.0)
    bottom = z0 + radius
    rings = []  # (ring radius, z, normal z-component scale)
    for i in range(cap_rings + 1):  # bottom hemisphere, pole to equator
        a = -math.pi / 2 + (math.pi / 2) * i / cap_rings
        rings.append((math.cos(a), bottom + radius * math.sin(a), math.sin(a)))
    for i in range(cap_rings + 1):  # top hemisphere, equator to pole
        a = (math.pi / 2) * i / cap_rings
        rings.append((math.cos(a), bottom + straight + radius * math.sin(a), math.sin(a)))
    positions, normals, triangles = [], [], []
    for c, z, s in rings:
        for k in range(segments):
            t = 2 * math.pi * k / segments
            nx, ny = c * math.cos(t), c * math.sin(t)
            positions.append((radius * nx, radius * ny, z))
            normals.append((nx, ny, s))
    for r in range(len(rings) - 1):
        for k in range(segments):
            a = r * segments + k
            b = r * segments + (k + 1) % segments
            c_ = (r + 1) * segments + k
            d = (r + 1) * segments + (k + 1) % segments
            if rings[r][0] > 1e-9:
                triangles.append((a, b, d))
            if rings[r + 1][0] > 1e-9:
                triangles.append((a, d, c_))
    return positions, normals, triangles


def cylinder(radius, length, segments, axis, center):
    """A closed cylinder along `axis` ("y" or "z") centred at `center`, with flat caps."""
    def place(x, y, z):
        if axis == "y":  # map local z to world y
            x, y, z = x, -z, y
        return (x + center[0], y + center[1], z + center[2])

    def orient(x, y, z):
        return (x, -z, y) if axis == "y" else (x, y, z)

    positions, normals, triangles = [], [], []
    half = length / 2
    for z, nz in ((-half, 0.0), (half, 0.0)):  # side rings
        for k in range(segments):
            t = 2 * math.pi * k / segments
            positions.append(place(radius * math.cos(t), radius * math.sin(t), z))
            normals.append(orient(math.cos(t), math.sin(t), nz))
    for k in range(segments):
        a, b = k, (k + 1) % segments
        triangles.append((a, b, segments + b))
        triangles.append((a, segments + b, segments + a))
    for z, nz in ((-half, -1.0), (half, 1.0)):  # caps: a centre and a ring each
        centre = len(positions)
        positions.append(place(0, 0, z))
        normals.append(orient(0, 0, nz))
        for k in range(segments):
            t = 2 * math.pi * k / segments
            positions.append(place(radius * math.cos(t), radius * math.sin(t), z))
            normals.append(orient(0, 0, nz))
        for k in range(segments):
            a, b = centre + 1 + k, centre + 1 + (k + 1) % segments
            triangles.append((centre, b, a) if nz < 0 else (centre, a, b))
    return positions, normals, triangles


def box(size, center):
    """A box as 12 triangles with flat normals."""
    sx, sy, sz = (s / 2 for s in size)
    positions, normals, triangles = [], [], []
    faces = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    for n, u, v in faces:
        base = len(positions)
        for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = [n[i] * (sx, sy, sz)[i] + du * u[i] * (sx, sy, sz)[i] + dv * v[i] * (sx, sy, sz)[i]
                 for i in range(3)]
            positions.append(tuple(p[i] + center[i] for i in range(3)))
            normals.append(n)
        triangles += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return positions, normals, triangles


def write_obj(path, parts, mtl_name):
    """parts: list of (material, (positions, normals, triangles))."""
    lines = ["# generated by assets/tools/make_arm.py", "mtllib %s" % mtl_name]
    offset = 1
    for material, (positions, normals, triangles) in parts:
        lines.append("usemtl %s" % material)
        lines += ["v %.6f %.6f %.6f" % p for p in positions]
        lines += ["vn %.6f %.6f %.6f" % n for n in normals]
        lines += ["f %d//%d %d//%d %d//%d" % (a + offset, a + offset, b + offset, b + offset,
                                               c + offset, c + offset) for a, b, c in triangles]
        offset += len(positions)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return sum(len(t) for _, (_, _, t) in parts)


def write_mtl(path):
    with open(path, "w") as f:
        f.write("# generated by assets/tools/make_arm.py\n")
        for name, rgb in (("shell", SHELL), ("accent", ACCENT), ("dark", DARK)):
            f.write("newmtl %s\nKd %.3f %.3f %.3f\nKs 0.3 0.3 0.3\nNs 40\nd 1\n\n" % ((name,) + rgb))


def write_stl(path, mesh):
    positions, _, triangles = mesh
    with open(path, "wb") as f:
        f.write(b"pixelgym arm collision hull".ljust(80, b" "))
        f.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            pa, pb, pc = positions[a], positions[b], positions[c]
            u = [pb[i] - pa[i] for i in range(3)]
            v = [pc[i] - pa[i] for i in range(3)]
            n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write(struct.pack("<12fH", *(x / length for x in n), *pa, *pb, *pc, 0))


def write_dae(path, mesh, rgb):
    positions, normals, triangles = mesh
    flat_p = " ".join("%.6f" % x for p in positions for x in p)
    flat_n = " ".join("%.6f" % x for n in normals for x in n)
    flat_t = " ".join("%d %d" % (i, i) for t in triangles for i in t)
    text = """<?xml version="1.0" encoding="utf-8"?>
<!-- generated by assets/tools/make_arm.py -->
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_effects>
    <effect id="pedestal-effect"><profile_COMMON><technique sid="common"><phong>
      <diffuse><color>%.3f %.3f %.3f 1</color></diffuse>
    </phong></technique></profile_COMMON></effect>
  </library_effects>
  <library_materials>
    <material id="pedestal-material"><instance_effect url="#pedestal-effect"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="pedestal-mesh"><mesh>
      <source id="pedestal-positions"><float_array id="pedestal-positions-array" count="%d">%s</float_array>
        <technique_common><accessor source="#pedestal-positions-array" count="%d" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <source id="pedestal-normals"><float_array id="pedestal-normals-array" count="%d">%s</float_array>
        <technique_common><accessor source="#pedestal-normals-array" count="%d" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="pedestal-vertices"><input semantic="POSITION" source="#pedestal-positions"/></vertices>
      <triangles material="pedestal-material" count="%d">
        <input semantic="VERTEX" source="#pedestal-vertices" offset="0"/>
        <input semantic="NORMAL" source="#pedestal-normals" offset="1"/>
        <p>%s</p>
      </triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="pedestal" name="pedestal">
      <instance_geometry url="#pedestal-mesh"><bind_material><technique_common>
        <instance_material symbol="pedestal-material" target="#pedestal-material"/>
      </technique_common></bind_material></instance_geometry>
    </node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
""" % (rgb + (3 * len(positions), flat_p, len(positions), 3 * len(normals), flat_n, len(normals),
              len(triangles), flat_t))
    with open(path, "w") as f:
        f.write(text)
    return len(triangles)


def cylinder_inertia(mass, radius, length):
    side = mass * (3 * radius * radius + length * length) / 12
    return side, side, mass * radius * radius / 2


def main():
    os.makedirs(MESHES, exist_ok=True)
    write_mtl(os.path.join(MESHES, "arm.mtl"))
    triangles = {}

    pedestal = cylinder(PEDESTAL_RADIUS, PEDESTAL_HEIGHT, SEGMENTS, "z", (0, 0, PEDESTAL_HEIGHT / 2))
    triangles["pedestal.dae"] = write_dae(os.path.join(MESHES, "pedestal.dae"), pedestal, DARK)

    for index, (name, axis, length, radius, _, _, _, _) in enumerate(LINKS):
        parts = [("shell", capsule(radius, length + radius, SEGMENTS, CAP_RINGS, -radius / 2))]
        next_axis = LINKS[index + 1][1] if index + 1 < len(LINKS) else "z"
        if next_axis == "y":  # a motor housing across the next (bending) joint
            parts.append(("accent", cylinder(radius * 1.08, radius * 2.3, SEGMENTS, "y", (0, 0, length))))
        else:  # a collar below the next (twisting) joint
            parts.append(("accent", cylinder(radius * 1.06, radius * 0.6, SEGMENTS, "z", (0, 0, length - radius * 0.3))))
        triangles[name + ".obj"] = write_obj(os.path.join(MESHES, name + ".obj"), parts, "arm.mtl")
        hull = capsule(radius, length + radius, HULL_SEGMENTS, 3, -radius / 2)
        write_stl(os.path.join(MESHES, name + "_collision.stl"), hull)

    hand = [("dark", box((0.09, 0.16, 0.04), (0, 0, 0.02))),
            ("accent", box((0.02, 0.02, 0.08), (0, 0.06, 0.08))),
            ("accent", box((0.02, 0.02, 0.08), (0, -0.06, 0.08)))]
    triangles["hand.obj"] = write_obj(os.path.join(MESHES, "hand.obj"), hand, "arm.mtl")

    urdf = ['<?xml version="1.0"?>',
            "<!-- generated by assets/tools/make_arm.py: a 7-DOF arm with mesh links; do not edit",
            "     by hand. Triangles: %s -->" % ", ".join("%s %d" % kv for kv in sorted(triangles.items())),
            '<robot name="arm">',
            '  <link name="base">',
            '    <inertial><origin xyz="0 0 0.08"/><mass value="6.0"/>',
            '      <inertia ixx="%.6f" ixy="0" ixz="0" iyy="%.6f" iyz="0" izz="%.6f"/></inertial>'
            % cylinder_inertia(6.0, PEDESTAL_RADIUS, PEDESTAL_HEIGHT),
            '    <visual><geometry><mesh filename="meshes/pedestal.dae"/></geometry></visual>',
            '    <collision><origin xyz="0 0 0.08"/><geometry><cylinder radius="%.3f" length="%.3f"/></geometry></collision>'
            % (PEDESTAL_RADIUS, PEDESTAL_HEIGHT),
            "  </link>"]
    parent, offset = "base", PEDESTAL_HEIGHT
    for name, axis, length, radius, mass, lower, upper, effort in LINKS:
        ixx, iyy, izz = cylinder_inertia(mass, radius, length)
        urdf += ['  <link name="%s">' % name,
                 '    <inertial><origin xyz="0 0 %.4f"/><mass value="%.2f"/>' % (length / 2, mass),
                 '      <inertia ixx="%.6f" ixy="0" ixz="0" iyy="%.6f" iyz="0" izz="%.6f"/></inertial>' % (ixx, iyy, izz),
                 '    <visual><geometry><mesh filename="meshes/%s.obj"/></geometry></visual>' % name,
                 '    <collision><geometry><mesh filename="meshes/%s_collision.stl"/></geometry></collision>' % name,
                 "  </link>",
                 '  <joint name="joint%s" type="revolute">' % name[-1],
                 '    <parent link="%s"/><child link="%s"/>' % (parent, name),
                 '    <origin xyz="0 0 %.4f"/>' % offset,
                 '    <axis xyz="%s"/>' % ("0 0 1" if axis == "z" else "0 1 0"),
                 '    <limit lower="%.2f" upper="%.2f" effort="%.1f" velocity="2.0"/>' % (lower, upper, effort),
                 '    <dynamics damping="0.5" friction="0.0"/>',
                 "  </joint>"]
        parent, offset = name, length
    urdf += ['  <link name="hand">',
             '    <inertial><origin xyz="0 0 0.03"/><mass value="0.4"/>',
             '      <inertia ixx="0.0009" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0009"/></inertial>',
             '    <visual><geometry><mesh filename="meshes/hand.obj"/></geometry></visual>',
             '    <collision><origin xyz="0 0 0.02"/><geometry><box size="0.09 0.16 0.04"/></geometry></collision>',
             '    <collision><origin xyz="0 0.06 0.08"/><geometry><box size="0.02 0.02 0.08"/></geometry></collision>',
             '    <collision><origin xyz="0 -0.06 0.08"/><geometry><box size="0.02 0.02 0.08"/></geometry></collision>',
             "  </link>",
             '  <joint name="hand_joint" type="fixed">',
             '    <parent link="%s"/><child link="hand"/>' % parent,
             '    <origin xyz="0 0 %.4f"/>' % offset,
             "  </joint>",
             '  <link name="end_effector"/>',
             '  <joint name="end_effector_joint" type="fixed">',
             '    <parent link="hand"/><child link="end_effector"/>',
             '    <origin xyz="0 0 0.12"/>',
             "  </joint>",
             "</robot>"]
    with open(os.path.join(OUT, "arm.urdf"), "w") as f:
        f.write("\n".join(urdf) + "\n")
    print("wrote %s: %d visual triangles" % (OUT, sum(triangles.values())))


if __name__ == "__main__":
    main()
