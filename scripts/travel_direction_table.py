#!/usr/bin/env python3
# Writes the page relating cam_from_lidar's rotation error to the adjusted cameras' travel direction
# (Markdown, to stdout):
#   travel_direction_table.py VARIANT SCENE:RESULTS_TSV:WORK_DIR[:LABEL] ...
# RESULTS_TSV is a results file of benchmark_uncertainty.sh (scene, seed, errors, sigmas, z); the
# run of a SCENE row is WORK_DIR/SCENE-SEED with the joint adjuster's output in joint-VARIANT, and
# COLMAP's images-only adjustment started at the truth in true_pose_landmarks/adjusted
# (scripts/true_pose_model.sh) where there is one. LABEL names the family (default SCENE). Per run,
# the direction of travel of each step between consecutive frames, in the step's first camera (the
# relative pose's translation direction, what the images' focus of expansion measures), from the
# adjusted cameras (camera_poses_tum.txt) and from the truth (dataset/ground_truth/
# cam_from_world.txt); its error as a pitch (about the camera x axis, positive: travel seen upwards)
# and a yaw (about the camera y axis), weighted by the step length. On a drive that does not turn,
# E_l ties the cameras' travel to the LiDAR's through cam_from_lidar's rotation: the two pitch
# errors are one direction.
import datetime, math, os, sys

from landmark_offset_table import data_lines, read_images, rotation


def transposed_times(r, v):
    return tuple(sum(r[i][j] * v[i] for i in range(3)) for j in range(3))


def world_from_cam(r, t):
    """(world_from_cam rotation, camera centre) of a cam_from_world rotation r and translation t."""
    return tuple(zip(*r)), tuple(-c for c in transposed_times(r, t))


def truth_poses(path):
    """world_from_cam per station of a cam_from_world file, in station order."""
    return [world_from_cam(rotation(*map(float, f[1:5])), tuple(map(float, f[5:8])))
            for f in sorted((line.split() for line in data_lines(path)), key=lambda f: f[0])]


def tum_poses(path):
    poses = []
    for f in (line.split() for line in data_lines(path)):
        qx, qy, qz, qw = map(float, f[4:8])
        poses.append((rotation(qw, qx, qy, qz), tuple(map(float, f[1:4]))))
    return poses


def colmap_poses(model):
    """world_from_cam per image of a TXT model, in station order."""
    return [world_from_cam(r, t) for r, t, _, _, _ in
            sorted(read_images(model).values(), key=lambda image: image[3])]


def travel_angles(poses):
    """Step-weighted pitch and yaw [deg] of each step's direction in its first camera."""
    pitch = yaw = total = 0.0
    for (r, c), (_, c_next) in zip(poses, poses[1:]):
        d = transposed_times(r, tuple(b - a for a, b in zip(c, c_next)))
        length = math.sqrt(sum(x * x for x in d))
        pitch += length * math.degrees(math.atan2(-d[1], d[2]))
        yaw += length * math.degrees(math.atan2(d[0], d[2]))
        total += length
    return pitch / total, yaw / total


def travel_error(poses, truth):
    """Pitch and yaw error of the travel direction [deg]; None without one pose per station."""
    if len(poses) != len(truth):
        return None
    (pe, ye), (pt, yt) = travel_angles(poses), travel_angles(truth)
    return pe - pt, ye - yt


def rows_of(variant, scene, results, work, label):
    rows = []
    for line in open(results):
        f = line.rstrip('\n').split('\t')
        if len(f) < 20 or f[0] != scene:
            continue
        run = os.path.join(work, f'{f[0]}-{f[1]}')
        truth = truth_poses(os.path.join(run, 'dataset/ground_truth/cam_from_world.txt'))
        joint = travel_error(tum_poses(os.path.join(run, f'joint-{variant}/camera_poses_tum.txt')),
                             truth)
        adjusted = os.path.join(run, 'true_pose_landmarks/adjusted')
        images = (travel_error(colmap_poses(adjusted), truth)
                  if os.path.exists(os.path.join(adjusted, 'images.txt')) else None)
        if joint:
            rows.append((label, f[1], len(truth), float(f[2]), float(f[14]), joint[0],
                         float(f[3]), float(f[15]), joint[1], images))
    return rows


def mean(values):
    return sum(values) / len(values)


def correlation(a, b):
    ma, mb = mean(a), mean(b)
    sab = sum((x - ma) * (y - mb) for x, y in zip(a, b))
    saa, sbb = sum((x - ma) ** 2 for x in a), sum((y - mb) ** 2 for y in b)
    return sab / math.sqrt(saa * sbb) if saa > 0 and sbb > 0 else float('nan')


def cell(value, digits=4):
    return '' if value is None or math.isnan(value) else f'{value:+.{digits}f}'


def median(values):
    values = sorted(values)
    return (values[(len(values) - 1) // 2] + values[len(values) // 2]) / 2 if values else None


kDriftedDeg = 1.0  # an images-only adjustment whose travel moved this far has drifted off


def drifted(images):
    return images is not None and max(abs(images[0]), abs(images[1])) > kDriftedDeg


def images_only(rows, k):
    """Median over the runs whose images-only adjustment did not drift, and their number."""
    kept = [r[9][k] for r in rows if r[9] and not drifted(r[9])]
    return median(kept), len(kept)


def images_cell(rows, k):
    value, count = images_only(rows, k)
    return f'{cell(value)} ({count} runs)' if count else ''


def summary(rows):
    print('| family | runs | frames | mean err rx | mean travel pitch err | corr. | images only: '
          'median travel pitch err | mean err ry | mean travel yaw err | corr. | images only: '
          'median travel yaw err |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for label in dict.fromkeys(r[0] for r in rows):
        own = [r for r in rows if r[0] == label]
        column = lambda k: [r[k] for r in own]
        print(f'| {label} | {len(own)} | {own[0][2]} | {cell(mean(column(3)))} | '
              f'{cell(mean(column(5)))} | {cell(correlation(column(3), column(5)), 2)} | '
              f'{images_cell(own, 0)} | {cell(mean(column(6)))} | {cell(mean(column(8)))} | '
              f'{cell(correlation(column(6), column(8)), 2)} | {images_cell(own, 1)} |')


def main():
    variant = sys.argv[1]
    rows = []
    for argument in sys.argv[2:]:
        scene, results, work, *label = argument.split(':')
        rows += rows_of(variant, scene, results, work, label[0] if label else scene)
    print('# cam_from_lidar\'s rotation error and the cameras\' travel direction\n')
    print(f'Written by `scripts/benchmark_travel_direction.sh` on {datetime.date.today()}, joint '
          f'adjuster variant `{variant}`, on the front ends of `scripts/benchmark_uncertainty.sh`.')
    print('Errors against the truth: cam_from_lidar\'s rotation vector about the camera x (pitch) '
          'and y (yaw) axes [deg] with z = error / reported sigma; the direction of travel between '
          'consecutive frames in the earlier frame\'s camera minus the true one [deg], weighted by '
          'the step length, of the joint adjuster\'s cameras and of COLMAP\'s images-only bundle '
          'adjustment started at the true poses (the images\' own optimum: no LiDAR, no '
          'cam_from_lidar). corr.: correlation over the runs of the error of cam_from_lidar and '
          'that of the joint\'s travel direction. The images-only columns give the median over '
          'the runs whose adjustment did not drift off (travel moved by less than 1 deg; COLMAP\'s '
          'adjustment of a forward-moving single camera, whose scale is free, drifts in some '
          'runs; empty cells).\n')
    summary(rows)
    print('\n| family | seed | err rx | z rx | travel pitch err | images only | err ry | z ry | '
          'travel yaw err | images only |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        images = (None, None) if not r[9] or drifted(r[9]) else r[9]
        print(f'| {r[0]} | {r[1]} | {r[3]:+.4f} | {r[4]:+.2f} | {r[5]:+.4f} | {cell(images[0])} | '
              f'{r[6]:+.4f} | {r[7]:+.2f} | {r[8]:+.4f} | {cell(images[1])} |')


main()
