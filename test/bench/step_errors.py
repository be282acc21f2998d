#!/usr/bin/python3
"""Per-step errors of an estimated trajectory against the truth: for every two consecutive
estimated frames, the estimated relative motion T_{k-1,k} against the true one (ground-truth poses
at the nearest stamps, within --max-difference s). A wrong step is one whose translation error
exceeds --max-translation (m) or whose rotation error exceeds --max-rotation (deg): at a
sub-sampled rate these are the steps the odometry got wrong, whatever its status said.

Usage: /usr/bin/python3 test/bench/step_errors.py --gt GT.txt --est EST.txt
Prints: steps N, wrong_steps K, median_step_error_m, p95_step_error_m, median_step_error_deg,
median_true_step_m, median_true_step_deg (one "key value" per line).
"""
import argparse
import math
import sys

import numpy as np

from tum_trajectory import read_tum_trajectory


def angle_deg(R):
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--gt", required=True)
    p.add_argument("--est", required=True)
    p.add_argument("--max-difference", type=float, default=0.02)
    p.add_argument("--max-translation", type=float, default=0.05)
    p.add_argument("--max-rotation", type=float, default=5.0)
    a = p.parse_args()
    gt = read_tum_trajectory(a.gt)
    est = read_tum_trajectory(a.est)
    if not gt or len(est) < 2:
        sys.exit("step_errors: need a ground truth and at least two estimated poses")
    gt_stamps = np.array([s for s, _ in gt])

    def truth(stamp):
        i = int(np.argmin(np.abs(gt_stamps - stamp)))
        return gt[i][1] if abs(gt_stamps[i] - stamp) <= a.max_difference else None

    t_err, r_err, t_true, r_true = [], [], [], []
    wrong = 0
    for (s0, E0), (s1, E1) in zip(est, est[1:]):
        G0, G1 = truth(s0), truth(s1)
        if G0 is None or G1 is None:
            continue
        step_est = np.linalg.inv(E0) @ E1
        step_true = np.linalg.inv(G0) @ G1
        D = np.linalg.inv(step_true) @ step_est
        te, re = float(np.linalg.norm(step_est[:3, 3] - step_true[:3, 3])), angle_deg(D[:3, :3])
        t_err.append(te)
        r_err.append(re)
        t_true.append(float(np.linalg.norm(step_true[:3, 3])))
        r_true.append(angle_deg(step_true[:3, :3]))
        wrong += te > a.max_translation or re > a.max_rotation
    if not t_err:
        sys.exit("step_errors: no step has ground truth at both ends")
    print("steps %d" % len(t_err))
    print("wrong_steps %d" % wrong)
    print("median_step_error_m %.6f" % float(np.median(t_err)))
    print("p95_step_error_m %.6f" % float(np.percentile(t_err, 95)))
    print("median_step_error_deg %.4f" % float(np.median(r_err)))
    print("median_true_step_m %.6f" % float(np.median(t_true)))
    print("median_true_step_deg %.4f" % float(np.median(r_true)))


if __name__ == "__main__":
    main()
