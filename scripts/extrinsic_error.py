#!/usr/bin/env python3
# Per-axis error of an estimated cam_from_lidar against a reference, in units of the reported sigma:
#   extrinsic_error.py TRUTH ESTIMATE REPORT_JSON [LABEL...]
# TRUTH, ESTIMATE: pose files (qw qx qy qz tx ty tz, '#' comments), or a rig.json as ESTIMATE (its
# cam_from_lidar_guess); REPORT_JSON may be '' (no sigmas). Prints one tab-separated line:
# the labels, the errors (rotation vector of estimate * inverse(truth) about the camera axes [deg],
# translation [mm]), the reported sigmas and z = error / sigma ('nan' for an axis reported without a
# sigma: undetermined or held). A report whose uncertainty was not computed gives the labels,
# 'FAILED' and the report's message instead, as a failed run does in the benchmarks' results.
import json, math, sys


def read_pose(path):
    if path.endswith('.json'):
        guess = json.load(open(path))['cam_from_lidar_guess']
        return guess['rotation'], guess['translation']
    values = [float(v) for line in open(path) if line.strip() and not line.startswith('#')
              for v in line.split()]
    return values[:4], values[4:7]


def multiply(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return [aw*bw - ax*bx - ay*by - az*bz, aw*bx + ax*bw + ay*bz - az*by,
            aw*by - ax*bz + ay*bw + az*bx, aw*bz + ax*by - ay*bx + az*bw]


def errors(truth_path, estimate_path):
    (qt, tt), (qe, te) = read_pose(truth_path), read_pose(estimate_path)
    d = multiply(qe, [qt[0], -qt[1], -qt[2], -qt[3]])
    if d[0] < 0:
        d = [-v for v in d]
    s = math.sqrt(d[1]**2 + d[2]**2 + d[3]**2)
    angle = 2 * math.atan2(s, d[0])
    rotation = [math.degrees(angle) * v / s if s > 0 else 0.0 for v in d[1:]]
    return rotation + [1000 * (e - t) for e, t in zip(te, tt)]


def sigmas(report_path):
    if not report_path:
        return [float('nan')] * 6
    u = json.load(open(report_path))['uncertainty']
    if 'sigma_deg_mm' in u:
        return [float('nan') if v is None else v for v in u['sigma_deg_mm']]
    covariance = u['covariance_deg_mm']
    return [math.sqrt(covariance[k][k]) for k in range(6)]


def main():
    truth, estimate, report = sys.argv[1:4]
    uncertainty = json.load(open(report))['uncertainty'] if report else {}
    if report and 'sigma_deg_mm' not in uncertainty and 'covariance_deg_mm' not in uncertainty:
        message = 'no covariance: ' + uncertainty.get('message', '')
        print('\t'.join(sys.argv[4:] + ['FAILED', message]))
        return
    e, s = errors(truth, estimate), sigmas(report)
    z = [ek / sk if sk > 0 else float('nan') for ek, sk in zip(e, s)]  # nan > 0 is False
    print('\t'.join(sys.argv[4:] + ['%.4f' % v for v in e] + ['%.4f' % v for v in s] +
                    ['%.3f' % v for v in z]))


if __name__ == '__main__':
    main()
