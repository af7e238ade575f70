#!/usr/bin/env python3
# Writes the end-to-end coverage page (Markdown, to stdout) from benchmark_uncertainty.sh's results.tsv:
#   uncertainty_table.py RESULTS_TSV STATIONS LIDAR_POINTS
import datetime, math, os, sys
path, stations, points = sys.argv[1:]
axes = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']
rows = [line.rstrip('\n').split('\t') for line in open(path) if line.strip()]
print('# Coverage of the reported cam_from_lidar uncertainty, end to end\n')
drive_only = all(r[0].startswith('street_drive') for r in rows)
print('Written by `scripts/benchmark_uncertainty.sh` on %s (%d cores)' %
      (datetime.date.today().isoformat(), os.cpu_count()) + ('.\n' if drive_only else ':'))
if not drive_only:
    print('Per scene and seed, %s stations, '
          '%s LiDAR rays per station, full-resolution images; stereo depth, COLMAP SIFT, LiDAR '
          'registration, hand-eye initialisation without a guess, joint adjustment with default '
          'options.\n' % (stations, points))
print('Errors are the rotation vector of estimate * inverse(truth) about the camera axes [deg] and the '
      'translation error [mm]; z = error / reported sigma (report.json `covariance_deg_mm`).\n')
if any(r[0] == 'street_drive' for r in rows):
    print('`street_drive`: the simulated street drive instead of tripod stations: one camera, 40 frames '
          '(`DRIVE_FRAMES`), 120000 rays per sweep, no guess, the whole `pipeline` with sequential '
          'matching (de-skewed sweeps, moving cars left out, similarity hand-eye, E_m at the moving '
          "platform's weight); `report.json` marks these sigmas as not validated by coverage.\n")
if any(r[0] == 'street_drive_stereo' for r in rows):
    print('`street_drive_stereo`: the same drive with the second camera: stereo depth and depth priors, '
          'the planar hand-eye refined by the stereo-LiDAR alignment (`initialization.json` '
          '`stereo_alignment`), E_m at the moving platform\'s weight.\n')
def cell(value, fmt):
    return 'undet.' if math.isnan(float(value)) else fmt % float(value)


print('| scene | seed | ' + ' | '.join('err ' + a for a in axes) + ' | ' +
      ' | '.join('z ' + a for a in axes) + ' | ' + ' | '.join('sigma ' + a for a in axes) + ' |')
print('|---|---|' + '---|' * 18)
for r in rows:
    if r[2] == 'FAILED':
        print('| %s | %s | failed |' % (r[0], r[1]) + ' |' * 17)
        continue
    errors = ['%.4f' % float(v) if k < 3 else '%.1f' % float(v) for k, v in enumerate(r[2:8])]
    print('| %s | %s | ' % (r[0], r[1]) + ' | '.join(errors) + ' | ' +
          ' | '.join(cell(v, '%.2f') for v in r[14:20]) + ' | ' +
          ' | '.join(cell(v, '%.4f') for v in r[8:14]) + ' |')
print('\nErrors and sigmas: rotation in deg, translation in mm; "undet." = held at the start and '
      'reported without a sigma (not counted below).\n')
print('| scene | runs | ' + ' | '.join('beyond 2 sigma ' + a for a in axes) +
      ' | rms z (determined axes) | undetermined axes |')
print('|---|---|' + '---|' * 8)
for scene in sorted({r[0] for r in rows}) + ['all']:
    ok = [r for r in rows if r[2] != 'FAILED' and (scene == 'all' or r[0] == scene)]
    if not ok: continue
    misses = []
    for k in range(6):
        z = [float(r[14 + k]) for r in ok if not math.isnan(float(r[14 + k]))]
        misses.append('%d of %d' % (sum(abs(v) > 2 for v in z), len(z)))
    determined = [float(r[14 + k]) for r in ok for k in range(6) if not math.isnan(float(r[14 + k]))]
    rms = math.sqrt(sum(v * v for v in determined) / len(determined)) if determined else float('nan')
    undetermined = sum(math.isnan(float(r[14 + k])) for r in ok for k in range(6))
    print('| %s | %d | %s | %.2f | %d |' % (scene, len(ok), ' | '.join(misses), rms, undetermined))
