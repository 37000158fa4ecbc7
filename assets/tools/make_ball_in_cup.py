#!/usr/bin/env python3
"""Generates pixelgym's ball in cup (BallInCupCatch): assets/ball_in_cup/ball_in_cup.urdf.

Usage: python3 assets/tools/make_ball_in_cup.py   (writes assets/ball_in_cup/ball_in_cup.urdf)

The model is dm_control's ball_in_cup (suite/ball_in_cup.xml) written as a URDF: a cup of five
capsules (radius 8 mm, a U open at the top, 0.1 m wide and deep) on a slider along x and a slider
along z, each with a spring of 20 N/m towards the start, damping 3 N s/m and a motor of 5 N; and a
ball (radius 25 mm) on a slider along x and a slider along z with nothing on them. Neither turns.
Masses at 1000 kg/m^3, as dm_control's. Slider positions of 0 are dm_control's qpos0: the cup at
(0, 0, 0.6), the ball at (0, 0, 0.2).

The links that carry the x sliders have 0.1 g each (the simulator needs some mass there; the
cup and the ball have 65 g). The string between the ball and the cup is not in the URDF: the
task adds it to the world (World::add_string).
Standard library only; running it again gives an identical file.
"""
import os

from planar import (Sphere, link_inertial, link_xml, segment, slider_links, slider_xml,
                    urdf_start, write_urdf)

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "ball_in_cup", "ball_in_cup.urdf"))

MATERIALS = {"self": (0.7, 0.5, 0.3), "effector": (0.7, 0.4, 0.2)}
WALL = 0.008
# dm_control's cup_part_0 .. 4, fromto (x, z) in the cup's frame.
CUP = [segment((-0.05, 0.0), (-0.05, -0.075), WALL),
       segment((-0.05, -0.075), (-0.025, -0.1), WALL),
       segment((-0.025, -0.1), (0.025, -0.1), WALL),
       segment((0.025, -0.1), (0.05, -0.075), WALL),
       segment((0.05, -0.075), (0.05, 0.0), WALL)]
BALL = [Sphere((0.0, 0.0), 0.025, material="effector")]


def main():
    out = urdf_start("ball_in_cup", "make_ball_in_cup.py", "ball_in_cup.xml", MATERIALS)
    out.append("  <link name=\"base\"/>\n")
    out.append(slider_links(("cup_x_slider", "ball_x_slider"), mass=1e-4, inertia=1e-8))
    for name, shapes in (("cup", CUP), ("ball", BALL)):
        mass, com, inertia = link_inertial(shapes)
        out.append(link_xml(name, shapes, mass, com, inertia))
    out.append(slider_xml("cup_x", "base", "cup_x_slider", (0, 0, 0.6), (1, 0, 0), 5.0, 3.0,
                          20.0))
    out.append(slider_xml("cup_z", "cup_x_slider", "cup", (0, 0, 0), (0, 0, 1), 5.0, 3.0, 20.0))
    out.append(slider_xml("ball_x", "base", "ball_x_slider", (0, 0, 0.2), (1, 0, 0), 0.0, 0.0))
    out.append(slider_xml("ball_z", "ball_x_slider", "ball", (0, 0, 0), (0, 0, 1), 0.0, 0.0))
    write_urdf(OUT, out)

if __name__ == "__main__":
    main()
