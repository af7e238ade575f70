#!/usr/bin/env python3
# The page of scripts/benchmark_straight_drive.sh from its results:
#   straight_drive_table.py RESULTS_TSV GUESS_DEG GUESS_M [PIXEL_SAMPLES (default 1)]
# RESULTS_TSV lines: rig, seed, guess (0|1), 'start' or 'result', then extrinsic_error.py's errors
# (6), sigmas (6) and z (6); or rig, seed, guess, 'FAILED', the first error line.
import datetime, math, subprocess, sys

AXES = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']


def read(path):
    runs, failed = {}, []
    for line in open(path):
        fields = line.rstrip('\n').split('\t')
        key = tuple(fields[:3])
        if fields[3] == 'FAILED':
            failed.append((key, fields[4] if len(fields) > 4 else ''))
            continue
        values = [float(v) for v in fields[4:22]]
        runs.setdefault(key, {})[fields[3]] = values
    return runs, failed


def number(value, digits):
    return 'undet.' if math.isnan(value) else '%.*f' % (digits, value)


def row(key, run):
    start, result = run['start'][:6], run['result']
    errors, z = result[:6], result[12:18]
    # Rotation in deg, translation in mm: a 1e-4 deg / 0.1 mm tie is no farther.
    tolerance = [1e-4] * 3 + [0.1] * 3
    no_farther = all(abs(e) <= abs(s) + t for e, s, t in zip(errors, start, tolerance))
    determined = [v for v in z if not math.isnan(v)]
    within = all(abs(v) <= 3 for v in determined)
    digits = [4] * 3 + [1] * 3
    cells = ([key[0], key[1], 'guess' if key[2] == '1' else 'none (pose initialiser)'] +
             [number(v, d) for v, d in zip(start, digits)] +
             [number(v, d) for v, d in zip(errors, digits)] +
             [number(v, 2) for v in z] +
             ['yes' if no_farther else 'no', 'yes' if within else 'no'])
    return '| ' + ' | '.join(cells) + ' |', no_farther, within


def main():
    runs, failed = read(sys.argv[1])
    guess_deg, guess_m = sys.argv[2], sys.argv[3]
    pixel_samples = sys.argv[4] if len(sys.argv) > 4 else '1'
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], capture_output=True,
                            text=True).stdout.strip()
    print('# A drive that never turns\n')
    print('Written by `scripts/benchmark_straight_drive.sh` on %s, commit %s (2 cores).\n' %
          (datetime.date.today().isoformat(), commit))
    print('`simulate_dataset --scene street --motion straight_drive`: the street drive in one lane '
          'without a turn, 0.5-1 m per frame, 120000 rays per sweep, %s rays per pixel axis; '
          'the whole `pipeline` with '
          'sequential matching. Each rig and seed runs twice: without a guess (the pose initialiser '
          'starts cam_from_lidar from the direction of travel and the structure both sensors see), '
          'and with rig.json\'s guess %s deg / %s m off the truth (no sigma).\n' %
          (pixel_samples, guess_deg, guess_m))
    print('Errors: the rotation vector of estimate * inverse(truth) about the camera axes [deg], '
          'the translation [mm]; z = error / reported sigma; "undet." = held at the start and '
          'reported without a sigma. "No farther" compares every axis of the result with the '
          'start\'s.\n')
    print('| rig | seed | start | ' + ' | '.join('start ' + a for a in AXES) + ' | ' +
          ' | '.join('err ' + a for a in AXES) + ' | ' + ' | '.join('z ' + a for a in AXES) +
          ' | no farther than the start | within 3 sigma |')
    print('|' + '---|' * 23)
    tally = {}
    for key in sorted(runs):
        if 'start' not in runs[key] or 'result' not in runs[key]:
            continue
        line, no_farther, within = row(key, runs[key])
        print(line)
        counts = tally.setdefault((key[0], key[2]), [0, 0, 0])
        counts[0] += 1
        counts[1] += no_farther
        counts[2] += within
    for key, message in failed:
        print('| %s | %s | %s | failed: %s |' % (key[0], key[1], 'guess' if key[2] == '1' else
                                                 'none', message.replace('|', '/')))
    print('\n| rig | start | runs | failed | no farther than the start on every axis | '
          'within 3 sigma on the determined axes |')
    print('|---|---|---|---|---|---|')
    for rig in ('mono', 'stereo'):
        for guess in ('0', '1'):
            counts = tally.get((rig, guess), [0, 0, 0])
            num_failed = sum(1 for key, _ in failed if key[0] == rig and key[2] == guess)
            print('| %s | %s | %d | %d | %d | %d |' % (rig, 'guess' if guess == '1' else 'none',
                                                      counts[0], num_failed, counts[1],
                                                      counts[2]))
    start_dependence(runs)


def start_dependence(runs):
    """Both runs of a seed share the data; their results' difference per axis, over the mean of
    their sigmas, says how far the result depends on where the adjustment starts."""
    print('\n## Same data, two starts\n')
    print('Both runs of a seed use the same simulated drive (rig.json differs only by the guess). '
          'Per axis: the result with the guess minus the result without, over the mean of the two '
          'reported sigmas. A result that depended only on the data would differ by far less than '
          'one sigma.\n')
    print('| rig | seed | ' + ' | '.join('diff ' + a for a in AXES) + ' | ' +
          ' | '.join('diff/sigma ' + a for a in AXES) + ' |')
    print('|' + '---|' * 14)
    for rig, seed in sorted({(key[0], key[1]) for key in runs}):
        pair = [runs.get((rig, seed, guess), {}).get('result') for guess in ('0', '1')]
        if None in pair:
            continue
        diff = [b - a for a, b in zip(pair[0][:6], pair[1][:6])]
        sigma = [(a + b) / 2 for a, b in zip(pair[0][6:12], pair[1][6:12])]
        ratio = [d / s if s > 0 else float('nan') for d, s in zip(diff, sigma)]
        digits = [4] * 3 + [1] * 3
        print('| %s | %s | ' % (rig, seed) +
              ' | '.join(number(v, d) for v, d in zip(diff, digits)) + ' | ' +
              ' | '.join(number(v, 1) for v in ratio) + ' |')


if __name__ == '__main__':
    main()
