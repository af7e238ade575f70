#!/usr/bin/env python3
# Writes docs/benchmarks/error_sources.md (Markdown, to stdout) from the results of
# scripts/benchmark_error_sources.sh:
#   error_sources_table.py NEAREST_TSV SCENE:KIND:RESULTS_TSV ...
# Per family and kind of image data: errors beyond 2 sigma per axis, rms z, the mean and rms error
# per axis over the seeds every kind has; then every run, and every run's nearest landmark
# (NEAREST_TSV: scene, seed, kind, depth [m], point3D id, image id; scripts/nearest_landmark.py).
import datetime, os, sys

from variant_table import (kErrorsLegend, load, print_runs_table, print_summary_header, seed_key,
                           summary_row)

kKinds = ('default', 'exact_noise', 'exact', 'surface')
kKindText = {
    'default': "SIFT's keypoints (as the pipeline gives them)",
    'exact_noise': "exact projections at the true poses of COLMAP's landmarks triangulated there, "
                   "plus Gaussian noise of SIFT's rms residual there",
    'exact': 'the same exact projections without noise: the images agree with the true poses; the '
             'landmarks keep their offsets from the surfaces',
    'surface': 'exact projections, without noise, of the landmarks moved onto the true surfaces '
               '(true depth maps): no image error is left',
}


def print_nearest_table(path):
    nearest = {}
    for line in open(path):
        scene, seed, kind, depth = line.split('\t')[:4]
        nearest.setdefault((scene, seed), {})[kind] = float(depth)
    print('\nThe nearest landmark of each run\'s result: its smallest depth in a camera that observes '
          'it [m]. Nothing in the simulated scenes is nearer than about 5 m to a camera; a landmark '
          'near the focus of expansion, whose depth the images hardly determine, can slide along '
          'the direction of travel into a later camera\'s centre, where the derivatives of its '
          'projection grow as 1/depth and it outweighs the rest of the data.\n')
    print('| family | seed | ' + ' | '.join(kKinds) + ' |')
    print('|---|---|' + '---|' * len(kKinds))
    for key in sorted(nearest, key=seed_key):
        print('| %s | %s | ' % key + ' | '.join(
            '%.3g' % nearest[key][k] if k in nearest[key] else '' for k in kKinds) + ' |')


def main():
    results = {}  # scene -> kind -> (runs, failed)
    for argument in sys.argv[2:]:
        scene, kind, path = argument.split(':', 2)
        results.setdefault(scene, {})[kind] = load(path)
    print('# Where cam_from_lidar\'s error on a simulated drive comes from\n')
    print('Written by `scripts/benchmark_error_sources.sh` on %s (%d cores). Per family and seed the '
          'front end of [uncertainty.md](uncertainty.md) is made once; the joint adjuster then runs '
          'with its default options on it with the keypoints (in the database and the initial '
          'model) replaced by `scripts/synthetic_keypoints.py`:\n' % (
              datetime.date.today().isoformat(), os.cpu_count()))
    for kind in kKinds:
        print('- `%s`: %s.' % (kind, kKindText[kind]))
    if 'street_drive_20' in results:
        print('\n`street_drive_20` is the street drive\'s first 20 frames (those of '
              '`kitti_layout_drive`) in the simulator\'s own layout, which has the true depth maps '
              'that the KITTI layout lacks (`benchmark_uncertainty.sh` makes its front ends).')
    print('\nFrom one kind to the next one error source goes: SIFT\'s systematic keypoint errors '
          '(default to exact_noise), the keypoint noise (exact_noise to exact), the landmarks\' '
          'offsets from the surfaces that E_m sees (exact to surface). What `surface` keeps comes '
          'from the LiDAR side (range noise, the sweeps\' registration) and the estimator. '
          'Keypoints outside the true-pose tracks keep SIFT\'s positions.\n')
    print(kErrorsLegend + ' Only the seeds that every kind of the family has are summarised.\n')
    print_summary_header()
    all_keys, names = [], []
    for scene in sorted(results):
        kinds = [k for k in kKinds if k in results[scene]]
        keys = set.intersection(*(set(results[scene][k][0]) for k in kinds))
        all_keys += sorted(keys, key=seed_key)
        for kind in kinds:
            runs = results[scene][kind][0]
            print(summary_row(scene, kind, [runs[key] for key in sorted(keys, key=seed_key)]))
    for scene in sorted(results):
        for kind, (_, failed) in results[scene].items():
            for key in sorted(failed, key=seed_key):
                print('\nLeft out: %s seed %s failed with %s keypoints (%s).' % (
                    key[0], key[1], kind, failed[key]))
    for kind in kKinds:
        merged = {}
        for scene in results:
            merged.update(results[scene].get(kind, ({}, {}))[0])
        names.append((kind, merged))
    print_runs_table(all_keys, names)
    print_nearest_table(sys.argv[1])


if __name__ == '__main__':
    main()
