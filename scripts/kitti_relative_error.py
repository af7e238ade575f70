#!/usr/bin/env python3
"""KITTI's relative trajectory error, computed independently of colmap-lidar's C++ (plain Python).

usage: kitti_relative_error.py ESTIMATE.txt REFERENCE.txt [LENGTHS_M]

Both files hold one 3x4 row-major world_from_sensor pose per line (KITTI odometry format), frame k
on line k. For every first frame i and segment length L, j is the first frame whose path length
along the reference from i reaches L; E = (est_i^-1 est_j)^-1 (ref_i^-1 ref_j); the translation error
is |t(E)| / L and the rotation error the angle of E over L. Prints JSON: the mean over all (i, L)
samples in % and deg/m, per length, and the end-to-end drift (|t(E)| of the first and last frame
over the path length, %). LENGTHS_M: comma-separated; default 10, 20, ... up to the path length
(at most 800).
"""
import json
import math
import sys


def read_poses(path):
    poses = []
    with open(path) as f:
        for line in f:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            v = [float(x) for x in line.split()]
            poses.append([v[0:4], v[4:8], v[8:12], [0.0, 0.0, 0.0, 1.0]])
    return poses


def multiply(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


def inverse(m):
    rt = [[m[c][r] for c in range(3)] for r in range(3)]
    t = [-sum(rt[r][k] * m[k][3] for k in range(3)) for r in range(3)]
    return [rt[0] + [t[0]], rt[1] + [t[1]], rt[2] + [t[2]], [0.0, 0.0, 0.0, 1.0]]


def error(est, ref, i, j):
    a = multiply(inverse(est[i]), est[j])
    b = multiply(inverse(ref[i]), ref[j])
    e = multiply(inverse(a), b)
    translation = math.sqrt(sum(e[r][3] ** 2 for r in range(3)))
    # atan2 of sine and cosine: acos alone loses small angles to rounding near 1.
    cosine = 0.5 * (e[0][0] + e[1][1] + e[2][2] - 1.0)
    sine = 0.5 * math.sqrt((e[2][1] - e[1][2]) ** 2 + (e[0][2] - e[2][0]) ** 2 + (e[1][0] - e[0][1]) ** 2)
    return translation, math.degrees(math.atan2(sine, cosine))


def main():
    est, ref = read_poses(sys.argv[1]), read_poses(sys.argv[2])
    if len(est) != len(ref) or len(ref) < 2:
        sys.exit("the two files need the same number of poses, at least 2")
    dist = [0.0]
    for k in range(1, len(ref)):
        dist.append(dist[-1] + math.sqrt(sum((ref[k][r][3] - ref[k - 1][r][3]) ** 2 for r in range(3))))
    if len(sys.argv) > 3:
        lengths = [float(x) for x in sys.argv[3].split(",")]
    else:
        lengths = [10.0 * n for n in range(1, 81) if 10.0 * n <= dist[-1] + 1e-9]
    samples, per_length = [], []
    for length in lengths:
        found = []
        for i in range(len(ref)):
            j = next((k for k in range(i, len(ref)) if dist[k] >= dist[i] + length), None)
            if j is None:
                break
            t, r = error(est, ref, i, j)
            found.append((t / length, r / length))
        samples += found
        n = len(found)
        per_length.append({"length_m": length, "count": n,
                           "translation_percent": 100 * sum(s[0] for s in found) / n if n else 0.0,
                           "rotation_deg_per_m": sum(s[1] for s in found) / n if n else 0.0})
    n = len(samples)
    end_t, _ = error(est, ref, 0, len(ref) - 1)
    print(json.dumps({
        "num_segments": n,
        "translation_percent": 100 * sum(s[0] for s in samples) / n if n else None,
        "rotation_deg_per_m": sum(s[1] for s in samples) / n if n else None,
        "per_length": per_length,
        "end_to_end_drift_percent": 100 * end_t / dist[-1] if dist[-1] > 0 else 0.0,
        "path_length_m": dist[-1],
    }, indent=2))


if __name__ == "__main__":
    main()
