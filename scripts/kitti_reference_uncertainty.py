#!/usr/bin/env python3
# How well KITTI's own calibration knows cam_from_lidar: the standard deviation of the reference
# that the real-sample benchmarks compare against, estimated from two calibration days of the same
# vehicle (2011_09_28 and 2011_09_30, two days apart, same cameras and Velodyne).
#   kitti_reference_uncertainty.py RAW_0928_CALIBRATION_DIR ODOMETRY_CALIB_TXT
# Each day's velo_to_cam is an independent estimate of the same rigid transform, so their
# difference d has covariance 2 sigma_ref^2 (if both days are equally good and the rig did not move;
# if it moved, sigma_ref is overestimated). With one pair of days a per-axis estimate has one degree
# of freedom; sigma_ref is pooled per block: sigma_ref^2 = mean over the 3 axes of d^2 / 2.
# The comparison is made in the unrectified camera 0 (both days' cam0 is the same physical camera;
# each day's rectified frame is that day's R_rect_00 times it). The 2011_09_30 day's unrectified
# velo_to_cam and R_rect_00 are KITTI's published values for that day (raw data calibration files,
# not in ../shared/data); the script checks that their product is the odometry sample's Tr.
# Prints one tab-separated line: sigma_ref rotation [deg], translation [mm], then the six per-axis
# differences 09_28 - 09_30 (rotation vector about the camera 0 axes [deg], translation [mm]).
import math, sys

# KITTI raw 2011_09_30 calib_velo_to_cam.txt (R row-major, T [m]) and calib_cam_to_cam.txt R_rect_00.
kVeloToCam0930R = [7.027555e-03, -9.999753e-01, 2.599616e-05, -2.254837e-03, -4.184312e-05,
                   -9.999975e-01, 9.999728e-01, 7.027479e-03, -2.255075e-03]
kVeloToCam0930T = [-7.137748e-03, -7.482656e-02, -3.336324e-01]
kRect0930 = [9.999280e-01, 8.085985e-03, -8.866797e-03, -8.123205e-03, 9.999583e-01, -4.169750e-03,
             8.832711e-03, 4.241477e-03, 9.999520e-01]


def read_values(path, key):
    for line in open(path):
        if line.startswith(key + ':'):
            return [float(v) for v in line.split(':', 1)[1].split()]
    sys.exit('%s: no "%s:" line' % (path, key))


def matrix(values):
    return [values[3 * i:3 * i + 3] for i in range(3)]


def product(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(a, v):
    return [sum(a[i][k] * v[k] for k in range(3)) for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def rotation_vector_deg(r):
    angle = math.acos(max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2)))
    axis = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    scale = math.degrees(angle) / (2 * math.sin(angle)) if angle > 0 else 0.0
    return [scale * v for v in axis]


def main():
    raw_dir, odometry_calib = sys.argv[1:3]
    r28 = matrix(read_values(raw_dir + '/calib_velo_to_cam.txt', 'R'))
    t28 = read_values(raw_dir + '/calib_velo_to_cam.txt', 'T')
    r30, rect30 = matrix(kVeloToCam0930R), matrix(kRect0930)
    tr = read_values(odometry_calib, 'Tr')
    expected = [row + [t] for row, t in zip(product(rect30, r30), apply(rect30, kVeloToCam0930T))]
    mismatch = max(abs(expected[i][j] - tr[4 * i + j]) for i in range(3) for j in range(4))
    if mismatch > 1e-6:
        sys.exit('%s: Tr is not R_rect_00 * velo_to_cam of 2011_09_30 (off by %g)'
                 % (odometry_calib, mismatch))
    d_rotation = rotation_vector_deg(product(r28, transpose(r30)))
    d_translation = [1000 * (a - b) for a, b in zip(t28, kVeloToCam0930T)]
    sigma_rotation = math.sqrt(sum(v * v for v in d_rotation) / 6)
    sigma_translation = math.sqrt(sum(v * v for v in d_translation) / 6)
    print('\t'.join(['%.4f' % sigma_rotation, '%.2f' % sigma_translation] +
                    ['%.4f' % v for v in d_rotation] + ['%.2f' % v for v in d_translation]))


if __name__ == '__main__':
    main()
