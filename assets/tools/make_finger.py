#!/usr/bin/env python3
"""Generates pixelgym's finger (FingerSpin): assets/finger/finger.urdf.

Usage: python3 assets/tools/make_finger.py        (writes assets/finger/finger.urdf)

The model is dm_control's finger (suite/finger.xml) written as a URDF: a two-link finger on a
hinge 0.2 m left of centre and a free spinner on a hinge 0.2 m right of it, both 0.4 m up, every
hinge turning about -y. The same capsules and cylinders, their masses at 1000 kg/m^3, joint
ranges, damping and motor gears (proximal 30 N m, distal 15 N m). The distal link's long capsule
is drawn only, as dm_control's (contype 0): the finger touches the spinner with its tip, the
proximal capsule and the proximal cylinder.

Two things are written differently, with the same motion:
- dm_control gives the proximal joint ref -90 degrees, so that its drawn pose (hanging down) is
  q = -pi/2 and q = 0 points the finger at the spinner. Here the proximal joint's frame is
  turned -90 degrees about y instead: the same q gives the same pose.
- The spinner's damping is 0.03 N m s, the value dm_control's Spin sets when an episode starts
  (finger.xml has 0.5, which Turn keeps); its dry friction is 0.1 N m (frictionloss).

One URDF holds both chains from a fixed base with no shape; the task turns self-collision on so
that the finger and the spinner touch (parent and child links never do).
Standard library only; running it again gives an identical file.
"""
import math
import os

from planar import (Capsule, CylinderY, hinge_xml, link_inertial, link_xml, urdf_start,
                    write_urdf)

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "finger", "finger.urdf"))

# dm_control's materials (suite/common/materials.xml).
MATERIALS = {"self": (0.7, 0.5, 0.3), "effector": (0.7, 0.4, 0.2), "decoration": (0.3, 0.5, 0.7)}
DAMPING = 2.5

# Shapes in each link's frame (the joint's), as dm_control's bodies: (centre (x, z), ...).
PROXIMAL = [CylinderY((0.0, 0.0), 0.034, 0.033, material="decoration"),
            Capsule((0.0, -0.085), 0.0, 0.03, 0.085)]
DISTAL = [Capsule((0.0, -0.08), 0.0, 0.028, 0.08, collides=False),
          Capsule((0.0, -0.1455), 0.0, 0.03, 0.0155, material="effector")]
SPINNER = [Capsule((0.02, 0.0), 0.0, 0.04, 0.09), Capsule((-0.02, 0.0), 0.0, 0.04, 0.09),
           CylinderY((0.0, 0.0), 0.02, 0.045, material="decoration")]


def main():
    out = urdf_start("finger", "make_finger.py", "finger.xml", MATERIALS)
    out.append("  <link name=\"base\"/>\n")
    for name, shapes in (("proximal", PROXIMAL), ("distal", DISTAL), ("spinner", SPINNER)):
        mass, com, inertia = link_inertial(shapes)
        out.append(link_xml(name, shapes, mass, com, inertia))
    out.append(hinge_xml("proximal", "base", "proximal", (-0.2, 0.0, 0.4), (0, -1, 0),
                         (-110.0, 110.0), 30.0, DAMPING, rpy=(0.0, -math.pi / 2, 0.0)))
    out.append(hinge_xml("distal", "proximal", "distal", (0.0, 0.0, -0.18), (0, -1, 0),
                         (-110.0, 110.0), 15.0, DAMPING))
    out.append(hinge_xml("hinge", "base", "spinner", (0.2, 0.0, 0.4), (0, -1, 0), None, 0.0,
                         0.03, friction=0.1))
    write_urdf(OUT, out)

if __name__ == "__main__":
    main()
