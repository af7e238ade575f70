#!/usr/bin/env python3
# Writes the coverage page of the reported cam_from_lidar uncertainty (Markdown, to stdout) from
# benchmark_uncertainty.sh's results:
#   uncertainty_table.py RESULTS_TSV VARIANT JOINT_OPTIONS
# (environment START=truth: the runs started at the true cam_from_lidar; PIXEL_SAMPLES: the
# simulated drives' rays per pixel axis)
# A results line: scene, seed, the errors (rx ry rz [deg], tx ty tz [mm]), the sigmas and the z
# (scripts/extrinsic_error.py); 'nan' z: the axis is undetermined (held at the start, no sigma).
import datetime, math, os, sys

path, variant, joint_options = sys.argv[1:]
axes = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']
rows = [line.rstrip('\n').split('\t') for line in open(path) if line.strip()]
FAMILIES = {
    't_specimen': ('tripod', 'the T specimen: 8 tripod stations of the stereo pod, 300000 LiDAR rays '
                   'each, full-resolution images; hand-eye initialisation without a guess'),
    'bridge_pier': ('tripod', 'the bridge pier, as the T specimen'),
    'street_drive': ('drive', 'the simulated street drive, one camera, 40 frames, 120000 rays per '
                     'sweep, no guess; the pipeline with sequential matching (de-skewed sweeps, '
                     'moving cars left out)'),
    'street_drive_stereo': ('drive', 'the same drive with the second camera (stereo depth, depth '
                            'priors, the stereo-LiDAR alignment of the pose initialiser)'),
    'street_drive_20': ('drive', 'the street drive\'s first 20 frames (those of '
                        '`kitti_layout_drive`) in the simulator\'s own layout, with true depth '
                        'maps, one camera, no guess'),
    'straight_drive': ('drive', 'the street drive in one lane without a turn, one camera, 40 '
                       'frames, 120000 rays per sweep, no guess; the pipeline with sequential '
                       'matching'),
    'kitti_layout_drive': ('drive', '20 frames of the street drive in KITTI raw\'s layout (one '
                           'camera), imported by `import_kitti` with its seeded 1 deg / 5 cm guess'),
    'kitti_odometry': ('drive', 'the real KITTI odometry 04 sample (20 frames of a straight drive), '
                       'stereo and mono, no guess; the reference is KITTI\'s calibration, itself an '
                       'estimate (see [kitti_extrinsic.md](kitti_extrinsic.md))'),
    'kitti_odometry_halves': ('drive', 'the same sample\'s frames 0-9 (seed -1) and 10-19 (seed -2) '
                              'as two drives of their own, stereo and mono, no guess'),
}
# The 95 % quantile of chi-square with 0..6 degrees of freedom.
CHI2_95 = [0.0, 3.84, 5.99, 7.81, 9.49, 11.07, 12.59]
# The goals of a family: rotation error [deg], translation error on determined axes [mm].
GOALS = {'tripod': (0.05, 2.0), 'drive': (0.1, 20.0)}


def number(value):
    return float(value)


def cell(value, fmt):
    return 'undet.' if math.isnan(number(value)) else fmt % number(value)


def print_header():
    print('# Coverage of the reported cam_from_lidar uncertainty, over seeds and scene families\n')
    print('Written by `scripts/benchmark_uncertainty.sh` on %s (%d cores), estimator variant `%s`%s.'
          % (datetime.date.today().isoformat(), os.cpu_count(), variant,
             ' (`%s`)' % joint_options.strip() if joint_options.strip() else ''))
    start = ('the true cam_from_lidar (`START=truth`)' if os.environ.get('START') == 'truth'
             else 'the pose initialiser\'s cam_from_lidar')
    print('Per family and seed the front end is made once; the joint adjuster then runs alone on '
          'it, %s, from %s.\n' % ('with the options above' if joint_options.strip()
                                  else 'with its default options', start))
    for scene in sorted({r[0] for r in rows}):
        if scene in FAMILIES:
            print('- `%s`: %s.' % (scene, FAMILIES[scene][1]))
    if any(FAMILIES.get(r[0], ('',))[0] == 'drive' and not r[0].startswith('kitti_odometry')
           for r in rows):
        print('\nThe simulated drives\' images: %s rays per pixel axis (`simulate_dataset '
              '--pixel_samples`).' % os.environ.get('PIXEL_SAMPLES', '1'))
    print('\nErrors: the rotation vector of estimate * inverse(truth) about the camera axes [deg], the '
          'translation [mm]; z = error / reported sigma (`report.json` `uncertainty`); "undet." = held '
          'at the start and reported without a sigma.\n')


def print_runs():
    print('| scene | seed | ' + ' | '.join('err ' + a for a in axes) + ' | ' +
          ' | '.join('z ' + a for a in axes) + ' | ' + ' | '.join('sigma ' + a for a in axes) + ' |')
    print('|---|---|' + '---|' * 18)
    for r in rows:
        if r[2] == 'FAILED':
            print('| %s | %s | failed |' % (r[0], r[1]) + ' |' * 17)
            continue
        errors = ['%.4f' % number(v) if k < 3 else '%.1f' % number(v) for k, v in enumerate(r[2:8])]
        print('| %s | %s | ' % (r[0], r[1]) + ' | '.join(errors) + ' | ' +
              ' | '.join(cell(v, '%.2f') for v in r[14:20]) + ' | ' +
              ' | '.join(cell(v, '%.4f') for v in r[8:14]) + ' |')


def within_goals(r, goals):
    rotation = math.sqrt(sum(number(v) ** 2 for v in r[2:5]))
    determined = [abs(number(r[2 + k])) for k in range(3, 6) if not math.isnan(number(r[14 + k]))]
    return rotation <= goals[0], all(t <= goals[1] for t in determined)


def print_summary():
    print('\nPer family: errors beyond 2 sigma per axis (determined axes), rms z over the determined '
          'axes, the number of undetermined axes, and the runs within the goals (rotation angle; '
          'translation on every determined axis): 0.05 deg / 2 mm on tripods, 0.1 deg / 20 mm on '
          'drives.\n')
    print('| scene | runs | ' + ' | '.join('beyond 2 sigma ' + a for a in axes) +
          ' | rms z | undetermined axes | rotation within goal | translation within goal |')
    print('|---|---|' + '---|' * 10)
    for scene in sorted({r[0] for r in rows}):
        ok = [r for r in rows if r[0] == scene and r[2] != 'FAILED']
        if not ok:
            continue
        goals = GOALS[FAMILIES.get(scene, ('drive', ''))[0]]
        misses = []
        for k in range(6):
            z = [number(r[14 + k]) for r in ok if not math.isnan(number(r[14 + k]))]
            misses.append('%d of %d' % (sum(abs(v) > 2 for v in z), len(z)))
        determined = [number(r[14 + k]) for r in ok for k in range(6)
                      if not math.isnan(number(r[14 + k]))]
        rms = math.sqrt(sum(v * v for v in determined) / len(determined)) if determined else math.nan
        undetermined = sum(math.isnan(number(r[14 + k])) for r in ok for k in range(6))
        rotation_ok = sum(within_goals(r, goals)[0] for r in ok)
        translation_ok = sum(within_goals(r, goals)[1] for r in ok)
        print('| %s | %d | %s | %.2f | %d | %d of %d | %d of %d |' %
              (scene, len(ok), ' | '.join(misses), rms, undetermined, rotation_ok, len(ok),
               translation_ok, len(ok)))


def print_reference_z():
    """The real sample's z against the reference's own uncertainty (REFERENCE_TSV: the line of
    kitti_reference_uncertainty.py, its pooled sigmas first)."""
    real = [r for r in rows if r[0] == 'kitti_odometry' and r[2] != 'FAILED']
    if not real or not os.environ.get('REFERENCE_TSV'):
        return
    reference = [float(v) for v in open(os.environ['REFERENCE_TSV']).read().split()]
    sigma_reference = [reference[0]] * 3 + [reference[1]] * 3
    print('\nThe real sample\'s reference is itself an estimate, with a sigma of about %.3f deg and '
          '%.1f mm (KITTI\'s calibrations of two days, [kitti_extrinsic.md](kitti_extrinsic.md)). '
          'z_ref = error / sqrt(sigma^2 + sigma_ref^2) is the test of the reported sigma that this '
          'reference can make:\n' % (reference[0], reference[1]))
    print('| scene | rig | ' + ' | '.join('z_ref ' + a for a in axes) + ' |')
    print('|---|---|' + '---|' * 6)
    for r in real:
        z_ref = ['undet.' if math.isnan(number(s))
                 else '%.2f' % (number(v) / math.hypot(number(s), sigma_reference[k]))
                 for k, (v, s) in enumerate(zip(r[2:8], r[8:14]))]
        print('| %s | %s | ' % (r[0], r[1]) + ' | '.join(z_ref) + ' |')


def print_halves():
    """The real sample's two halves against each other: their errors share the reference, so the
    difference of the estimates tests the reported sigmas without it."""
    halves = {r[1]: r for r in rows if r[0] == 'kitti_odometry_halves' and r[2] != 'FAILED'}
    rigs = [rig for rig in ('stereo', 'mono') if rig + '-1' in halves and rig + '-2' in halves]
    if not rigs:
        return
    print('\nThe real sample\'s two halves (frames 0-9 and 10-19) calibrated apart: their estimates '
          'share no measurement and no reference, so z_12 = (estimate 1 - estimate 2) / '
          'sqrt(sigma_1^2 + sigma_2^2) tests the reported sigmas without KITTI\'s calibration. '
          'Errors common to both halves (the camera\'s and the LiDAR\'s own calibration) cancel '
          'in the difference: the test covers the errors that change along the drive. chi2 sums '
          'z_12^2 over the axes both halves determine (as if independent); 95 % of chi2 draws '
          'with that many axes lie below the bound.\n')
    print('| rig | ' + ' | '.join('diff ' + a for a in axes) + ' | ' +
          ' | '.join('z_12 ' + a for a in axes) + ' | chi2 | axes | 95 % bound |')
    print('|---|' + '---|' * 15)
    for rig in rigs:
        first, second = halves[rig + '-1'], halves[rig + '-2']
        diffs, zs = [], []
        for k in range(6):
            s1, s2 = number(first[8 + k]), number(second[8 + k])
            diff = number(first[2 + k]) - number(second[2 + k])
            undetermined = math.isnan(s1) or math.isnan(s2)
            diffs.append('undet.' if undetermined else ('%.4f' if k < 3 else '%.1f') % diff)
            zs.append(math.nan if undetermined else diff / math.hypot(s1, s2))
        determined = [z for z in zs if not math.isnan(z)]
        print('| %s | %s | %s | %.1f | %d | %.1f |' % (
            rig, ' | '.join(diffs), ' | '.join('undet.' if math.isnan(z) else '%.2f' % z for z in zs),
            sum(z * z for z in determined), len(determined), CHI2_95[len(determined)]))


print_header()
print_runs()
print_summary()
print_reference_z()
print_halves()
