#!/usr/bin/env python3
"""Writes the example dataset inputs beside this script (standard library only):

- surround-rig.yaml: a Kalibr camchain of four Kannala-Brandt fisheyes on a car-like body
  (x forward, y left, z up; the IMU is the body), looking forward, left, back and right:
  cam0 is placed by T_cam_imu, the others by T_cn_cnm1 from the one before, as Kalibr writes.
- room-loop.tum: 100 poses T_world_body at 10 Hz (TUM: t tx ty tz qx qy qz qw) driving a
  circle of radius 3.2 m, 1.5 m up, counter-clockwise, in a z-up world: render it in the
  y-up built-in room with --t-scene-world z-up.
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inverse(t):
    r = [[t[j][i] for j in range(3)] for i in range(3)]
    p = [-sum(r[i][k] * t[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [p[0]], r[1] + [p[1]], r[2] + [p[2]], [0.0, 0.0, 0.0, 1.0]]


def body_from_camera(forward, position):
    """T_body_cam of a level camera looking along `forward` (body axes), up the body's z."""
    z = forward
    y = [0.0, 0.0, -1.0]
    x = [y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]]
    return [[x[i], y[i], z[i], position[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


mounts = [
    ([1.0, 0.0, 0.0], [0.5, 0.0, 0.0]),
    ([0.0, 1.0, 0.0], [0.0, 0.3, 0.0]),
    ([-1.0, 0.0, 0.0], [-0.5, 0.0, 0.0]),
    ([0.0, -1.0, 0.0], [0.0, -0.3, 0.0]),
]
poses = [body_from_camera(f, p) for f, p in mounts]
lines = []
for n, pose in enumerate(poses):
    lines.append(f"cam{n}:")
    if n == 0:
        key, t = "T_cam_imu", inverse(pose)
    else:
        key, t = "T_cn_cnm1", matmul(inverse(pose), poses[n - 1])
    clean = [[0.0 if abs(v) < 1e-15 else v for v in row] for row in t]
    lines.append(f"  {key}:")
    for row in clean:
        lines.append("  - [" + ", ".join(f"{v:.1f}" for v in row) + "]")
    lines += [
        "  camera_model: pinhole",
        "  distortion_coeffs: [1.0e-2, -2.0e-3, 0.0, 0.0]",
        "  distortion_model: equidistant",
        "  intrinsics: [150.0, 150.0, 319.5, 239.5]",
        "  resolution: [640, 480]",
    ]
with open(os.path.join(HERE, "surround-rig.yaml"), "w") as f:
    f.write("\n".join(lines) + "\n")

with open(os.path.join(HERE, "room-loop.tum"), "w") as f:
    f.write("# timestamp tx ty tz qx qy qz qw (T_world_body, z up)\n")
    for i in range(100):
        t = 2 * math.pi * i / 100
        yaw = t + math.pi / 2
        f.write(
            f"{i / 10:.1f} {3.2 * math.cos(t):.6f} {3.2 * math.sin(t):.6f} 1.500000 "
            f"0.000000 0.000000 {math.sin(yaw / 2):.9f} {math.cos(yaw / 2):.9f}\n"
        )
