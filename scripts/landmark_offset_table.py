#!/usr/bin/env python3
"""Where COLMAP's landmarks sit relative to the true surface, at the true poses.

  landmark_offset_table.py true_model MODEL_TXT CAM_FROM_WORLD OUT_TXT
      MODEL_TXT's cameras and keypoints with the poses of CAM_FROM_WORLD (a simulated dataset's
      ground_truth/cam_from_world.txt) and no landmarks: the input of COLMAP's point_triangulator.
  landmark_offset_table.py table SEED:TRIANGULATED_TXT:DATASET ...
      Per landmark, from its observation in the nearest camera: the true surface point on that
      keypoint's ray (the dataset's rendered z-depth, a plane fitted in inverse depth over the 4 x 4
      pixels around it; non-planar neighbourhoods are skipped), the surface normal, and the signed
      offset of the landmark along it (positive: towards the camera). Prints markdown tables by the
      camera axis the surface faces and by distance, and by the cosine between ray and normal;
      then, by surface and the distance each keypoint is seen from, the keypoints' image rows
      against the landmark's projection.
  landmark_offset_table.py road_rows HEIGHT_M NAME:MODEL_TXT ...
      At each model's own poses (no truth needed): the keypoints' image rows against their
      landmark's projection for the landmarks about HEIGHT_M below the observing camera (the road
      under a car's camera), by the distance they are seen from.
"""
import math
import os
import struct
import sys

kMaxOffsetM = 0.05  # landmarks farther off the surface are mismatches, not offsets
kAxisNames = {0: "x (walls)", 1: "y (road)", 2: "z (facing the camera)"}
kDistanceBins = ((0, 5), (5, 10), (10, 20), (20, math.inf))
kCosineBins = ((0.0, 0.2), (0.2, 0.4), (0.4, 0.7), (0.7, 1.0001))


def data_lines(path):
    return [line for line in open(path) if line.strip() and not line.startswith("#")]


def rotation(qw, qx, qy, qz):
    return ((1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)),
            (2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)),
            (2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)))


def station_of(name):
    return os.path.splitext(os.path.basename(name))[0]


def true_model(model, truth_path, out):
    poses = {f[0]: f[1:8] for f in (line.split() for line in data_lines(truth_path))}
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "cameras.txt"), "w") as cameras:
        cameras.write(open(os.path.join(model, "cameras.txt")).read())
    open(os.path.join(out, "points3D.txt"), "w").close()
    lines = data_lines(os.path.join(model, "images.txt"))
    with open(os.path.join(out, "images.txt"), "w") as images:
        for k in range(0, len(lines) - 1, 2):
            fields = lines[k].split()
            fields[1:8] = poses[station_of(fields[9])]
            keypoints = lines[k + 1].split()
            images.write(" ".join(fields) + "\n" + " ".join(
                f"{keypoints[j]} {keypoints[j + 1]} -1" for j in range(0, len(keypoints), 3)) + "\n")


def read_cameras(model):
    """Camera id -> (fx, fy, cx, cy) of a TXT model's pinhole cameras."""
    return {int(f[0]): tuple(map(float, f[4:8])) for f in
            (line.split() for line in data_lines(os.path.join(model, "cameras.txt")))}


def to_camera(rot, trans, world):
    """A world point in a camera (rotation rows, translation)."""
    return tuple(dot(rot[r], world) + trans[r] for r in range(3))


def image_names(model):
    """Image id -> name of a TXT model's images."""
    lines = [line for line in open(os.path.join(model, "images.txt")) if not line.startswith("#")]
    return {int(lines[k].split()[0]): lines[k].split()[9] for k in range(0, len(lines) - 1, 2)}


def read_images(model):
    images = {}
    lines = [line for line in open(os.path.join(model, "images.txt")) if not line.startswith("#")]
    for k in range(0, len(lines) - 1, 2):
        f = lines[k].split()
        keypoints = lines[k + 1].split()
        xy = [(float(keypoints[j]), float(keypoints[j + 1])) for j in range(0, len(keypoints), 3)]
        images[int(f[0])] = (rotation(*map(float, f[1:5])), tuple(map(float, f[5:8])), int(f[8]),
                             station_of(f[9]), xy)
    return images


def read_depth(path):
    """A COLMAP depth map (width&height&channels& then float32, row major) as (width, rows)."""
    raw = open(path, "rb").read()
    header_end, ampersands = 0, 0
    while ampersands < 3:
        ampersands += raw[header_end:header_end + 1] == b"&"
        header_end += 1
    width, height, _ = map(int, raw[:header_end - 1].decode().split("&"))
    values = struct.unpack(f"<{width * height}f", raw[header_end:header_end + 4 * width * height])
    return width, height, values


def solve3(a, b):
    """x with a x = b for a 3 x 3 a (Cramer's rule); None if singular."""
    def det(m):
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    d = det(a)
    if abs(d) < 1e-300:
        return None
    return [det([[b[r] if c == k else a[r][c] for c in range(3)] for r in range(3)]) / d
            for k in range(3)]


def inverse_depth_plane(depth, u, v):
    """Coefficients (a, b, c) of 1/z = a u + b v + c over the 4 x 4 pixels around (u, v)."""
    width, height, values = depth
    c0, r0 = int(math.floor(u - 0.5)), int(math.floor(v - 0.5))
    if c0 < 1 or r0 < 1 or c0 + 2 >= width or r0 + 2 >= height:
        return None
    samples = []
    for row in range(r0 - 1, r0 + 3):
        for col in range(c0 - 1, c0 + 3):
            z = values[row * width + col]
            if z <= 0:
                return None
            samples.append((col + 0.5, row + 0.5, 1.0 / z))
    ata = [[0.0] * 3 for _ in range(3)]
    atb = [0.0] * 3
    for u_s, v_s, inverse in samples:
        row = (u_s, v_s, 1.0)
        for i in range(3):
            atb[i] += row[i] * inverse
            for j in range(3):
                ata[i][j] += row[i] * row[j]
    plane = solve3(ata, atb)
    if plane is None:
        return None
    worst = max(abs(1 / (plane[0] * s[0] + plane[1] * s[1] + plane[2]) - 1 / s[2]) for s in samples)
    median_depth = sorted(1 / s[2] for s in samples)[len(samples) // 2]
    return plane if worst <= 0.002 * median_depth else None


def backproject(camera, u, v, plane):
    z = 1.0 / (plane[0] * u + plane[1] * v + plane[2])
    return ((u - camera[2]) / camera[0] * z, (v - camera[3]) / camera[1] * z, z)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def image_row_residuals(images, cameras, world, track):
    """Per observation of a landmark (distance [m], keypoint row minus the landmark's projection
    [px])."""
    rows = []
    for j in range(0, len(track), 2):
        rot, trans, camera_id, _, keypoints = images[track[j]]
        in_cam = tuple(dot(rot[r], world) + trans[r] for r in range(3))
        camera = cameras[camera_id]
        if in_cam[2] > 0:
            row = camera[1] * in_cam[1] / in_cam[2] + camera[3]
            rows.append((norm(in_cam), keypoints[track[j + 1]][1] - row))
    return rows


def landmark_offsets(model, dataset):
    """Per landmark (facing axis, distance [m], cos(ray, normal), offset [m], its observations'
    image_row_residuals)."""
    cameras = read_cameras(model)
    images = read_images(model)
    depths = {}
    rows = []
    for line in data_lines(os.path.join(model, "points3D.txt")):
        f = line.split()
        world = tuple(map(float, f[1:4]))
        track = list(map(int, f[8:]))
        nearest = None
        for j in range(0, len(track), 2):
            rot, trans, _, _, _ = images[track[j]]
            in_cam = tuple(dot(rot[r], world) + trans[r] for r in range(3))
            if nearest is None or norm(in_cam) < norm(nearest[2]):
                nearest = (track[j], track[j + 1], in_cam)
        image_id, index, in_cam = nearest
        _, _, camera_id, station, keypoints = images[image_id]
        if station not in depths:
            depths[station] = read_depth(os.path.join(dataset, "ground_truth/depth", station + ".bin"))
        u, v = keypoints[index]
        plane = inverse_depth_plane(depths[station], u, v)
        if plane is None:
            continue
        camera = cameras[camera_id]
        surface = backproject(camera, u, v, plane)
        normal = cross(sub(backproject(camera, u + 1, v, plane), surface),
                       sub(backproject(camera, u, v + 1, plane), surface))
        normal = tuple(x / norm(normal) for x in normal)
        if dot(normal, surface) > 0:
            normal = tuple(-x for x in normal)  # towards the camera
        facing = max(range(3), key=lambda k: abs(normal[k]))
        cosine = abs(dot(normal, surface)) / norm(surface)
        rows.append((facing, norm(surface), cosine, dot(normal, sub(in_cam, surface)),
                     image_row_residuals(images, cameras, world, track)))
    return rows


def summary(values):
    n = len(values)
    mean = sum(values) / n
    spread = math.sqrt(sum((x - mean) ** 2 for x in values) / max(n - 1, 1))
    return n, sorted(values)[n // 2], mean, spread / math.sqrt(n)


def print_tables(rows):
    kept = [r for r in rows if abs(r[3]) < kMaxOffsetM]
    print("| surface faces | distance [m] | landmarks | median offset [mm] | mean [mm] | sem [mm] |")
    print("|---|---|---|---|---|---|")
    for axis in (1, 0, 2):
        for low, high in kDistanceBins:
            values = [1000 * r[3] for r in kept if r[0] == axis and low <= r[1] < high]
            if len(values) >= 10:
                n, median, mean, sem = summary(values)
                print(f"| {kAxisNames[axis]} | {low}-{high} | {n} | {median:+.2f} | {mean:+.2f} | "
                      f"{sem:.2f} |")
    print()
    print("| surface faces | cos(ray, normal) | landmarks | median offset / distance [mm/m] | "
          "mean [mm/m] | sem [mm/m] |")
    print("|---|---|---|---|---|---|")
    for axis in (1, 0):
        for low, high in kCosineBins:
            values = [1000 * r[3] / r[1] for r in kept if r[0] == axis and low <= r[2] < high]
            if len(values) >= 10:
                n, median, mean, sem = summary(values)
                print(f"| {kAxisNames[axis]} | {low:.1f}-{min(high, 1.0):.1f} | {n} | {median:+.3f} | "
                      f"{mean:+.3f} | {sem:.3f} |")
    print()
    print_row_residual_table(kept)


def print_row_residual_table(kept):
    """The observations' keypoint rows against the landmark's projection, by surface and distance:
    an offset that changes with the distance a keypoint is seen from is not absorbed by the
    landmark and moves the cameras."""
    print("| surface faces | observed from [m] | observations | mean keypoint row minus projection "
          "[px] | sem [px] |")
    print("|---|---|---|---|---|")
    for axis in (1, 0):
        for low, high in kDistanceBins:
            values = [r for landmark in kept if landmark[0] == axis
                      for d, r in landmark[4] if low <= d < high]
            if len(values) >= 10:
                n, _, mean, sem = summary(values)
                print(f"| {kAxisNames[axis]} | {low}-{high} | {n} | {mean:+.4f} | {sem:.4f} |")


def road_row_residuals(model, height_m):
    """Per observation of a landmark 0.35 m or less from height_m below its camera (camera y: the
    road under a camera height_m over it) (distance [m], keypoint row minus projection [px])."""
    cameras = read_cameras(model)
    images = read_images(model)
    rows = []
    for line in data_lines(os.path.join(model, "points3D.txt")):
        f = line.split()
        world = tuple(map(float, f[1:4]))
        track = list(map(int, f[8:]))
        for j in range(0, len(track), 2):
            rot, trans, _, _, _ = images[track[j]]
            below = dot(rot[1], world) + trans[1]
            if abs(below - height_m) <= 0.35:
                rows += image_row_residuals(images, cameras, world, track[j:j + 2])
    return rows


def print_road_rows(height_m, arguments):
    """The road's observations' keypoint rows against their landmark's projection, by distance, at
    each model's own poses (no truth needed)."""
    bins = ((0, 5), (5, 10), (10, 15), (15, 20), (20, 30), (30, math.inf))
    print(f"| model | observed from [m] | observations {height_m:g} m below the camera | mean "
          "keypoint row minus projection [px] | sem [px] |")
    print("|---|---|---|---|---|")
    for argument in arguments:
        name, model = argument.split(":", 1)
        rows = road_row_residuals(model, height_m)
        for low, high in bins:
            values = [r for d, r in rows if low <= d < high]
            if len(values) >= 10:
                n, _, mean, sem = summary(values)
                print(f"| {name} | {low}-{high} | {n} | {mean:+.4f} | {sem:.4f} |")


def main():
    if sys.argv[1] == "true_model":
        true_model(*sys.argv[2:5])
        return
    if sys.argv[1] == "road_rows":
        print_road_rows(float(sys.argv[2]), sys.argv[3:])
        return
    rows = []
    seeds = []
    for argument in sys.argv[2:]:
        seed, model, dataset = argument.split(":")
        seeds.append(seed)
        rows += landmark_offsets(model, dataset)
    print(f"Seeds: {', '.join(seeds)}; {len(rows)} landmarks on planar surfaces.\n")
    print_tables(rows)


if __name__ == "__main__":
    main()
