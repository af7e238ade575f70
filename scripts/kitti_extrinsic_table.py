#!/usr/bin/env python3
# Writes docs/benchmarks/kitti_extrinsic.md (to stdout) from benchmark_kitti_extrinsic.sh's results:
#   kitti_extrinsic_table.py RESULTS_TSV GUESS_DEG GUESS_M REFERENCE_TSV
# REFERENCE_TSV: kitti_reference_uncertainty.py's line (the reference's own sigma, pooled over two
# calibration days).
import datetime, math, os, subprocess, sys

path, guess_deg, guess_m, reference_path = sys.argv[1:]
reference = [float(v) for v in open(reference_path).read().split()]
sigma_reference = [reference[0]] * 3 + [reference[1]] * 3
axes = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']
rows = [line.rstrip('\n').split('\t') for line in open(path) if line.strip()]
commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], capture_output=True,
                        text=True).stdout.strip()
print('# cam_from_lidar on the real KITTI odometry sample\n')
print('Written by `scripts/benchmark_kitti_extrinsic.sh` on %s, commit %s (%d cores).\n' %
      (datetime.date.today().isoformat(), commit, os.cpu_count()))
print('Data: `../shared/data/kitti_odometry_04_sample`, 20 frames of a straight drive at ~13 m/s '
      '(HDL-64, rectified colour cameras), KITTI\'s calibration of 2011_09_30 as the reference. '
      'Each rig is started from that calibration perturbed by %s deg / %s m (`import_kitti '
      '--write_guess 1`); the whole `pipeline` runs once, then `joint_adjuster` in each variant on the '
      'same front end. Rows "no guess": rig.json without a guess; the start is the pose '
      'initialiser\'s (a straight drive: the travel direction and the structure).\n'
      % (guess_deg, guess_m))
print('Errors: rotation vector of estimate * inverse(reference) about the camera axes [deg], '
      'translation [mm]; z = error / reported sigma; "undet." = held at the start and reported '
      'without a sigma.\n')
print('The reference is itself an estimate. KITTI calibrated the same vehicle on 2011_09_28 and '
      '2011_09_30; the two days\' velo_to_cam differ by %s deg (rotation vector about camera 0\'s '
      'axes) and %s mm (`scripts/kitti_reference_uncertainty.py`). Pooled over the three axes of '
      'each block, the reference\'s own sigma is %.3f deg and %.1f mm (one pair of days: a rough '
      'estimate; too large if the rig moved between the days). z_ref = error / sqrt(sigma^2 + '
      'sigma_ref^2) is the test of the reported sigma that this reference can make: a sigma well '
      'below sigma_ref can be neither confirmed nor refuted by it.\n'
      % (' / '.join('%.3f' % v for v in reference[2:5]),
         ' / '.join('%.1f' % v for v in reference[5:8]), reference[0], reference[1]))
print('| rig | seed | estimator | ' + ' | '.join('err ' + a for a in axes) + ' | ' +
      ' | '.join('z ' + a for a in axes) + ' | ' + ' | '.join('z_ref ' + a for a in axes) + ' |')
print('|---|---|---|' + '---|' * 18)


def cell(value, digits):
    v = float(value)
    return '' if math.isnan(v) else ('%.' + str(digits) + 'f') % v


for r in rows:
    errors, sigmas, z = r[3:9], r[9:15], r[15:21]
    is_start = all(math.isnan(float(s)) for s in sigmas)
    zs = ['' if is_start else ('undet.' if math.isnan(float(zk)) else cell(zk, 1)) for zk in z]
    z_ref = ['' if is_start or math.isnan(float(s)) else
             cell(float(e) / math.hypot(float(s), sigma_reference[k]), 1)
             for k, (e, s) in enumerate(zip(errors, sigmas))]
    z_ref = [zr if zr or is_start else 'undet.' for zr in z_ref]
    print('| ' + ' | '.join(r[:3] + [cell(e, 3 if k < 3 else 1) for k, e in enumerate(errors)] +
                            zs + z_ref) + ' |')
print('\nEstimators: "default" = variance components estimated with the solve and, on this moving '
      'platform, the LiDAR clock offset as a parameter of E_m; "fixed weights, no clock offset" = '
      'the nominal weights (1 px, sigma_d, 2 cm) and one cam_from_lidar for every station; '
      '"nothing held" = the default with the hold thresholds lifted (`--hold_rotation_deg 1e9 '
      '--hold_translation_mm 1e9`): every direction of cam_from_lidar is estimated, however weakly '
      'the data determine it.')
