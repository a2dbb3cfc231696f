"""Parses a URDF with the PyPI `urdf-parser-py` package and prints one JSON object: the
robot's name, its links, and its joints in file order as {"name", "type", "parent", "child",
"axis", "xyz", "rpy", "limit"} (limit: [lower, upper, velocity] or null).

With a second argument, a JSON file {"name": [...], "frames": [[...], ...]} of joint
positions (rad), it also prints "fk": per frame, every link's origin in the root link's frame,
computed from the parsed joints as robot_state_publisher does (origin, then the rotation about
the axis), for comparison with the character's own forward kinematics; and "fk_rot": per
frame, every link's rotation in the root link's frame (3x3, rows).

Usage: read_urdf.py FILE.urdf [POSITIONS.json]
"""

import json
import math
import sys

import numpy as np
from urdf_parser_py.urdf import URDF


def rot_rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def rot_axis(axis, q):
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * (k @ k)


def fk(robot, positions):
    """Every link's (rotation, origin) in the root frame for {joint name: position}."""
    frames = {robot.get_root(): (np.eye(3), np.zeros(3))}
    pending = list(robot.joints)
    while pending:
        rest = []
        for j in pending:
            if j.parent not in frames:
                rest.append(j)
                continue
            pr, pt = frames[j.parent]
            o = j.origin
            xyz = np.asarray(o.xyz if o is not None and o.xyz is not None else [0, 0, 0], float)
            rpy = o.rpy if o is not None and o.rpy is not None else [0, 0, 0]
            r = pr @ rot_rpy(*rpy)
            t = pt + pr @ xyz
            if j.type in ("revolute", "continuous"):
                r = r @ rot_axis(j.axis, positions.get(j.name, 0.0))
            frames[j.child] = (r, t)
        if len(rest) == len(pending):
            raise SystemExit("joints not connected to the root: %s" % [j.name for j in rest])
        pending = rest
    return frames


def main():
    with open(sys.argv[1]) as f:
        robot = URDF.from_xml_string(f.read())
    joints = []
    for j in robot.joints:
        o = j.origin
        joints.append(
            {
                "name": j.name,
                "type": j.type,
                "parent": j.parent,
                "child": j.child,
                "axis": list(j.axis) if j.axis is not None else None,
                "xyz": list(o.xyz) if o is not None and o.xyz is not None else [0, 0, 0],
                "rpy": list(o.rpy) if o is not None and o.rpy is not None else [0, 0, 0],
                "limit": [j.limit.lower, j.limit.upper, j.limit.velocity]
                if j.limit is not None
                else None,
            }
        )
    out = {
        "name": robot.name,
        "links": [l.name for l in robot.links],
        "root": robot.get_root(),
        "joints": joints,
    }
    if len(sys.argv) > 2:
        with open(sys.argv[2]) as f:
            p = json.load(f)
        frames = [fk(robot, dict(zip(p["name"], frame))) for frame in p["frames"]]
        out["fk"] = [{k: list(map(float, v[1])) for k, v in f.items()} for f in frames]
        out["fk_rot"] = [{k: v[0].tolist() for k, v in f.items()} for f in frames]
    print(json.dumps(out))


if __name__ == "__main__":
    main()
