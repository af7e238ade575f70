#!/usr/bin/env python3
# Writes the page comparing two variants of the joint adjuster on the same front ends (Markdown, to
# stdout) from two results files of benchmark_uncertainty.sh:
#   variant_table.py BASE_TSV VARIANT_TSV VARIANT VARIANT_OPTIONS
# Only the runs present in both files (same scene and seed) are compared; failed runs are named.
# Per family and variant: errors beyond 2 sigma per axis, rms z, the mean and rms error per axis
# (determined axes only); then every run's errors and z with both variants.
import datetime, math, os, sys

axes = ['rx', 'ry', 'rz', 'tx', 'ty', 'tz']
kErrorsLegend = ('Errors: the rotation vector of estimate * inverse(truth) about the camera axes [deg], '
                 'the translation [mm]; z = error / reported sigma; undetermined axes (no sigma) are '
                 'left out of the counts.')


def load(path):
    """The runs with results, and the failed ones' messages, by (scene, seed)."""
    runs, failed = {}, {}
    for line in open(path):
        fields = line.rstrip('\n').split('\t')
        if len(fields) >= 20:
            runs[(fields[0], fields[1])] = [float(v) for v in fields[2:20]]
        elif len(fields) >= 3 and fields[2] == 'FAILED':
            failed[(fields[0], fields[1])] = ' '.join(fields[3:])
    return runs, failed


def seed_key(key):
    return (key[0], int(key[1]) if key[1].isdigit() else 0, key[1])


def error_cell(k, value):
    if math.isnan(value):
        return 'undet.'
    return '%+.4f' % value if k < 3 else '%+.1f' % value


def summary_row(family, name, rows):
    """One family's runs (error, sigma and z rows of extrinsic_error.py) under one variant."""
    misses, determined = [], []
    for a in range(6):
        z = [r[12 + a] for r in rows if not math.isnan(r[12 + a])]
        misses.append(str(sum(abs(v) > 2 for v in z)))
        determined += z
    rms_z = math.sqrt(sum(v * v for v in determined) / len(determined)) if determined else math.nan
    mean, rms = [], []
    for a in range(6):
        errors = [r[a] for r in rows if not math.isnan(r[12 + a])]  # determined axes only
        mean.append(sum(errors) / len(errors) if errors else math.nan)
        rms.append(math.sqrt(sum(e * e for e in errors) / len(errors)) if errors else math.nan)
    return '| %s | %s | %d | %s | %.2f | %s | %s |' % (
        family, name, len(rows), ' '.join(misses), rms_z,
        ' '.join(error_cell(a, mean[a]) for a in range(6)),
        ' '.join(error_cell(a, rms[a]).lstrip('+') for a in range(6)))


def print_summary_header():
    print('| family | variant | runs | beyond 2 sigma (rx ry rz tx ty tz) | rms z | mean error (rx ry rz '
          '[deg], tx ty tz [mm]) | rms error |')
    print('|---|---|---|---|---|---|---|')


def print_runs_table(keys, names):
    """Every run's errors and z, per variant (names: (variant, runs by key))."""
    print('\n| family | seed | variant | ' + ' | '.join('err ' + a for a in axes) + ' | ' +
          ' | '.join('z ' + a for a in axes) + ' |')
    print('|---|---|---|' + '---|' * 12)
    for key in keys:
        for name, runs in names:
            if key not in runs:
                continue
            r = runs[key]
            print('| %s | %s | %s | ' % (key[0], key[1], name) +
                  ' | '.join(error_cell(a, r[a]) for a in range(6)) + ' | ' +
                  ' | '.join('undet.' if math.isnan(v) else '%.2f' % v for v in r[12:18]) + ' |')


def main():
    base_path, variant_path, variant, options = sys.argv[1:]
    (base, base_failed), (other, other_failed) = load(base_path), load(variant_path)
    keys = sorted(set(base) & set(other), key=seed_key)
    families = sorted({k[0] for k in keys})
    names = [('default', base), (variant, other)]
    print('# The joint adjuster with `%s` against its default, on the same front ends\n' % variant)
    print('Written by `scripts/benchmark_estimator_variant.sh` on %s (%d cores), variant `%s`. The '
          'front ends and families are those of [uncertainty.md](uncertainty.md) '
          '(`scripts/benchmark_uncertainty.sh`); per family and seed the joint adjuster runs twice '
          'on the same initial model, with its default options and with `%s`.\n' % (
              datetime.date.today().isoformat(), os.cpu_count(), variant, options.strip()))
    print(kErrorsLegend + '\n')
    print_summary_header()
    for family in families:
        for name, runs in names:
            print(summary_row(family, name, [runs[k] for k in keys if k[0] == family]))
    for name, failed in (('default', base_failed), (variant, other_failed)):
        for key in sorted(failed, key=seed_key):
            print('\nLeft out: %s seed %s failed with %s (%s).' % (key[0], key[1], name, failed[key]))
    print_runs_table(keys, names)


if __name__ == '__main__':
    main()
