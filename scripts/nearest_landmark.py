#!/usr/bin/env python3
# The smallest depth of a landmark in a camera that observes it, over a binary COLMAP model:
#   nearest_landmark.py MODEL   ->  "<depth [m]>\t<point3D id>\t<image id>"
# A landmark near the focus of expansion of a forward-moving camera has an ill-determined depth and
# can slide along the direction of travel until it sits at a later camera's centre, where its
# projection's derivatives grow as 1/depth and it outweighs the rest of the data
# (docs/benchmarks/error_sources.md).
import struct, sys

from landmark_offset_table import rotation


def read_string(f):
    name = b""
    while (c := f.read(1)) != b"\0":
        name += c
    return name


def read_poses(path):
    """Image id -> (camera-from-world rotation rows, translation)."""
    poses = {}
    with open(path, "rb") as f:
        for _ in range(struct.unpack("<Q", f.read(8))[0]):
            image_id = struct.unpack("<I", f.read(4))[0]
            quaternion = struct.unpack("<4d", f.read(32))  # w first
            translation = struct.unpack("<3d", f.read(24))
            f.read(4)  # camera id
            read_string(f)
            f.seek(24 * struct.unpack("<Q", f.read(8))[0], 1)  # points2D
            poses[image_id] = (rotation(*quaternion), translation)
    return poses


def nearest(model):
    """(depth [m], point3D id, image id) of the nearest landmark observation."""
    poses = read_poses(model + "/images.bin")
    best = (float("inf"), 0, 0)
    with open(model + "/points3D.bin", "rb") as f:
        for _ in range(struct.unpack("<Q", f.read(8))[0]):
            point3D_id = struct.unpack("<Q", f.read(8))[0]
            xyz = struct.unpack("<3d", f.read(24))
            f.read(3 + 8)  # color, error
            length = struct.unpack("<Q", f.read(8))[0]
            track = struct.unpack("<%dI" % (2 * length), f.read(8 * length))
            for image_id in track[0::2]:
                rows, translation = poses[image_id]
                depth = sum(rows[2][k] * xyz[k] for k in range(3)) + translation[2]
                best = min(best, (depth, point3D_id, image_id))
    return best


if __name__ == "__main__":
    print("%.4g\t%d\t%d" % nearest(sys.argv[1]))
