#!/usr/bin/env python3
"""Asserts that every label (and the title) of mobility_server's markers projects inside rviz's 3D view.

    check_label_projection.py CONFIG.rviz WIDTHxHEIGHT [SERVER]   (needs a running master and server)

Reads the orbit camera of CONFIG (focal point, distance, yaw, pitch) and projects each TEXT_VIEW_FACING marker's
position with rviz's camera model: eye = focal + distance (cos p cos y, cos p sin y, sin p), looking at the
focal point with z up, vertical field of view 45 deg, aspect WIDTH / HEIGHT. Prints one line per label with its
pixel, and "N of M labels inside"; exit 0 when all are inside, 1 otherwise, 2 on bad input.
"""

import math
import sys

import rospy
import yaml
from visualization_msgs.msg import Marker, MarkerArray

FOV_Y = math.pi / 4.0


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1]) as f:
        config = yaml.safe_load(f)
    view = config["Visualization Manager"]["Views"]["Current"]
    width, height = (int(x) for x in sys.argv[2].split("x"))
    server = sys.argv[3] if len(sys.argv) > 3 else "/mobility_server"
    focal = [float(view["Focal Point"][k]) for k in "XYZ"]
    distance, yaw, pitch = float(view["Distance"]), float(view["Yaw"]), float(view["Pitch"])
    eye = [focal[0] + distance * math.cos(pitch) * math.cos(yaw),
           focal[1] + distance * math.cos(pitch) * math.sin(yaw),
           focal[2] + distance * math.sin(pitch)]
    forward = unit(sub(focal, eye))
    right = unit(cross(forward, [0.0, 0.0, 1.0]))
    up = cross(right, forward)
    tan_y = math.tan(FOV_Y / 2.0)
    tan_x = tan_y * width / height

    rospy.init_node("check_label_projection", anonymous=True)
    array = rospy.wait_for_message(server + "/markers", MarkerArray, timeout=30)
    inside = total = 0
    for m in array.markers:
        if m.action != Marker.ADD or m.type != Marker.TEXT_VIEW_FACING:
            continue
        if m.ns == "forces":
            continue  # hidden in rviz/mobility.rviz (launch forces:=true shows it, and the view then frames it)
        total += 1
        p = [m.pose.position.x, m.pose.position.y, m.pose.position.z]
        d = sub(p, eye)
        depth = dot(d, forward)
        if depth <= 0:
            print("OUTSIDE %s/%d '%s': behind the camera" % (m.ns, m.id, m.text))
            continue
        x = dot(d, right) / (depth * tan_x)
        y = dot(d, up) / (depth * tan_y)
        px, py = (x + 1.0) / 2.0 * width, (1.0 - y) / 2.0 * height
        ok = abs(x) <= 1.0 and abs(y) <= 1.0
        inside += ok
        print("%s %s/%d '%s' at pixel (%.0f, %.0f)" % ("inside " if ok else "OUTSIDE", m.ns, m.id, m.text, px, py))
    print("%d of %d labels inside the %dx%d view" % (inside, total, width, height))
    return 0 if total > 0 and inside == total else 1


if __name__ == "__main__":
    sys.exit(main())
