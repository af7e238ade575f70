#!/usr/bin/env python3
# Replaces a simulated front end's keypoints by synthetic ones whose errors are known, so that the
# joint adjuster can be run on image data with one error source at a time
# (scripts/benchmark_error_sources.sh):
#   synthetic_keypoints.py KIND TRUE_MODEL DATABASE INITIAL_MODEL OUTPUT_MODEL DATASET NOISE_PX SEED
#   synthetic_keypoints.py rms TRUE_MODEL   (SIFT's rms residual there per image axis [px])
# TRUE_MODEL: COLMAP's landmarks triangulated at the true poses (TXT, scripts/true_pose_model.sh).
# Every observation of its tracks gets, in DATABASE (changed in place: pass a copy) and in the
# initial model (TXT, written to OUTPUT_MODEL), the projection at the true pose of
#   KIND exact:   its triangulated landmark (the images agree with the true poses; the landmarks
#                 keep SIFT's offsets from the surfaces);
#   KIND surface: that landmark moved along the ray of its nearest observation onto the true surface
#                 (DATASET/ground_truth/depth; landmarks where no surface plane fits stay as in
#                 exact);
# plus Gaussian noise of NOISE_PX per image axis (random seed SEED; 0: none). Keypoints outside the
# tracks keep SIFT's positions. Prints the number of keypoints replaced and of landmarks moved.
import array, os, random, sqlite3, sys

import landmark_offset_table as offsets


def project(camera, in_cam):
    """Pixel (x, y) of a point in a pinhole camera (fx, fy, cx, cy); (None, None) behind it."""
    if in_cam[2] <= 0:
        return None, None
    fx, fy, cx, cy = camera
    return fx * in_cam[0] / in_cam[2] + cx, fy * in_cam[1] / in_cam[2] + cy


def surface_point(images, cameras, depths, dataset, world, track):
    """The true surface point on the ray of the landmark's nearest observation (world), or None."""
    def distance(j):
        return offsets.norm(offsets.to_camera(images[track[j]][0], images[track[j]][1], world))
    nearest = min(range(0, len(track), 2), key=distance)
    rot, trans, camera_id, station, keypoints = images[track[nearest]]
    if station not in depths:
        depths[station] = offsets.read_depth(
            os.path.join(dataset, "ground_truth/depth", station + ".bin"))
    u, v = keypoints[track[nearest + 1]]
    plane = offsets.inverse_depth_plane(depths[station], u, v)
    if plane is None:
        return None
    in_cam = offsets.sub(offsets.backproject(cameras[camera_id], u, v, plane), trans)
    return tuple(sum(rot[r][c] * in_cam[r] for r in range(3)) for c in range(3))


def synthetic_keypoints(kind, true_model, dataset, noise_px, seed):
    """(image name, keypoint index) -> synthetic (x, y), and the number of landmarks moved."""
    cameras = offsets.read_cameras(true_model)
    images = offsets.read_images(true_model)
    names = offsets.image_names(true_model)
    rng = random.Random(seed)
    depths, keypoints, moved = {}, {}, 0
    for line in offsets.data_lines(os.path.join(true_model, "points3D.txt")):
        f = line.split()
        world = tuple(map(float, f[1:4]))
        track = list(map(int, f[8:]))
        if kind == "surface":
            on_surface = surface_point(images, cameras, depths, dataset, world, track)
            if on_surface is not None:
                world, moved = on_surface, moved + 1
        for j in range(0, len(track), 2):
            rot, trans, camera_id, _, _ = images[track[j]]
            x, y = project(cameras[camera_id], offsets.to_camera(rot, trans, world))
            if x is not None:
                keypoints[(names[track[j]], track[j + 1])] = (
                    x + noise_px * rng.gauss(0, 1), y + noise_px * rng.gauss(0, 1))
    return keypoints, moved


def write_database(path, keypoints):
    connection = sqlite3.connect(path)
    image_ids = dict(connection.execute("SELECT name, image_id FROM images"))
    by_image = {}
    for (name, index), xy in keypoints.items():
        by_image.setdefault(name, []).append((index, xy))
    for name, items in by_image.items():
        cols, data = connection.execute("SELECT cols, data FROM keypoints WHERE image_id = ?",
                                        (image_ids[name],)).fetchone()
        values = array.array("f")
        values.frombytes(data)
        for index, (x, y) in items:
            values[index * cols], values[index * cols + 1] = x, y
        connection.execute("UPDATE keypoints SET data = ? WHERE image_id = ?",
                           (values.tobytes(), image_ids[name]))
    connection.commit()
    connection.close()


def write_model(initial_model, output_model, keypoints):
    os.makedirs(output_model, exist_ok=True)
    for name in ("cameras.txt", "points3D.txt"):
        with open(os.path.join(output_model, name), "w") as out:
            out.write(open(os.path.join(initial_model, name)).read())
    lines = [line for line in open(os.path.join(initial_model, "images.txt"))
             if not line.startswith("#")]
    with open(os.path.join(output_model, "images.txt"), "w") as out:
        for k in range(0, len(lines) - 1, 2):
            name = lines[k].split()[9]
            fields = lines[k + 1].split()
            for j in range(0, len(fields), 3):
                xy = keypoints.get((name, j // 3))
                if xy is not None:
                    fields[j], fields[j + 1] = repr(xy[0]), repr(xy[1])
            out.write(lines[k] + " ".join(fields) + "\n")


def residual_rms(true_model):
    """The rms of the observations' keypoint minus projection [px], over both image axes."""
    cameras = offsets.read_cameras(true_model)
    images = offsets.read_images(true_model)
    total, count = 0.0, 0
    for line in offsets.data_lines(os.path.join(true_model, "points3D.txt")):
        f = line.split()
        world = tuple(map(float, f[1:4]))
        track = list(map(int, f[8:]))
        for j in range(0, len(track), 2):
            rot, trans, camera_id, _, keypoints = images[track[j]]
            x, y = project(cameras[camera_id], offsets.to_camera(rot, trans, world))
            if x is not None:
                u, v = keypoints[track[j + 1]]
                total += (u - x) ** 2 + (v - y) ** 2
                count += 2
    return (total / count) ** 0.5


def main():
    if sys.argv[1] == "rms":
        print(f"{residual_rms(sys.argv[2]):.4f}")
        return
    kind, true_model, database, initial_model, output_model, dataset = sys.argv[1:7]
    noise_px, seed = float(sys.argv[7]), int(sys.argv[8])
    if kind not in ("exact", "surface"):
        sys.exit("synthetic_keypoints.py: KIND is exact or surface, not " + kind)
    keypoints, moved = synthetic_keypoints(kind, true_model, dataset, noise_px, seed)
    write_database(database, keypoints)
    write_model(initial_model, output_model, keypoints)
    print(f"{len(keypoints)} keypoints replaced; {moved} landmarks moved onto the surface")


if __name__ == "__main__":
    main()
