"""TUM trajectory files as 4x4 poses, for the benchmark scripts in test/bench (numpy only)."""
import math

import numpy as np


def read_tum_trajectory(path):
    """TUM trajectory -> [(stamp, 4x4 T_W_C)]."""
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            v = [float(x) for x in line.split()]
            rows.append((v[0], pose_from_tum(v[1:8])))
    return rows


def pose_from_tum(v):
    tx, ty, tz, qx, qy, qz, qw = v
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    qx, qy, qz, qw = qx / n, qy / n, qz / n, qw / n
    T = np.eye(4)
    T[:3, :3] = [
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
    ]
    T[:3, 3] = [tx, ty, tz]
    return T
