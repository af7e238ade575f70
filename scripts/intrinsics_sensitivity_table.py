#!/usr/bin/env python3
# Writes the intrinsics sensitivity page (Markdown, to stdout) from
# benchmark_intrinsics_sensitivity.sh's results:
#   intrinsics_sensitivity_table.py RESULTS_TSV
# A results line (scripts/extrinsic_error.py): change ('none': the calibration's intrinsics), half
# (1: frames 0-9, 2: frames 10-19), the errors (rx ry rz [deg], tx ty tz [mm]), sigmas and z;
# 'nan' sigma: the axis is undetermined (held at the start).
import datetime, math, os, sys

AXES = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']
rows = [line.rstrip('\n').split('\t') for line in open(sys.argv[1]) if line.strip()]
runs = {(r[0], r[1]): ([float(v) for v in r[2:8]], [float(v) for v in r[8:14]]) for r in rows}
changes = [r[0] for r in rows if r[0] != 'none' and r[1] == '1']


def cell(value, axis):
    if math.isnan(value):
        return 'undet.'
    return '%+.4f' % value if axis < 3 else '%+.1f' % value


def determined(k):
    return all(not math.isnan(runs[('none', h)][1][k]) for h in ('1', '2'))


print('# How the camera intrinsics move cam_from_lidar on the real sample\'s halves\n')
print('Written by `scripts/benchmark_intrinsics_sensitivity.sh` on %s (%d cores).' %
      (datetime.date.today().isoformat(), os.cpu_count()))
print('The joint adjuster holds the camera at its calibration. Here it runs again on the KITTI '
      'odometry sample\'s halves (frames 0-9 and 10-19, one camera, the front ends of '
      '`benchmark_uncertainty.sh`) with the initial model\'s camera changed, and each axis of '
      'cam_from_lidar moves by Δ (deg about, mm along the camera axes). Δ diff is the change of '
      'half 1 minus half 2, the difference that [uncertainty.md](uncertainty.md) tests against '
      'the halves\' sigmas; Δ diff / σ_12 is that change in units of the difference\'s sigma '
      '(sqrt(σ1² + σ2²)). Undetermined axes (held at the start) are not compared.\n')
print('| change | ' + ' | '.join('Δ %s half 1 | Δ %s half 2' % (a, a) for a in AXES[:5]) + ' |')
print('|---|' + '---|---|' * 5)
for change in changes:
    cells = []
    for k in range(5):
        for half in ('1', '2'):
            cells.append(cell(runs[(change, half)][0][k] - runs[('none', half)][0][k], k))
    print('| %s | %s |' % (change, ' | '.join(cells)))
print('\n| change | ' + ' | '.join('Δ diff %s | Δ diff / σ_12 %s' % (a, a) for a in AXES[:5]) +
      ' |')
print('|---|' + '---|---|' * 5)
for change in changes:
    cells = []
    for k in range(5):
        if not determined(k):
            cells += ['undet.', 'undet.']
            continue
        moved = [runs[(change, h)][0][k] - runs[('none', h)][0][k] for h in ('1', '2')]
        sigma = math.hypot(runs[('none', '1')][1][k], runs[('none', '2')][1][k])
        cells += [cell(moved[0] - moved[1], k), '%+.2f' % ((moved[0] - moved[1]) / sigma)]
    print('| %s | %s |' % (change, ' | '.join(cells)))
