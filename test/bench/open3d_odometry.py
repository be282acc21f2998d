#!/usr/bin/python3
"""Frame-to-frame Open3D odometry on a TUM-format RGB-D folder, as the peer baseline of
test/bench/odometry_benchmark.sh.

Usage:
  /usr/bin/python3 test/bench/open3d_odometry.py --seq SEQ_DIR --method METHOD --out TRAJ.txt
      [--timing TIMING.json] [--fx 525 --fy 525 --cx 319.5 --cy 239.5] [--depth-scale 5000]
      [--depth-max 4.5] [--init constant_velocity|identity] [--max-frames N] [--check-direction N]

SEQ_DIR holds depth.txt, rgb.txt (TUM lists: "stamp path") and, for --check-direction,
groundtruth.txt. METHOD is one of
  legacy_hybrid      open3d.pipelines.odometry.compute_rgbd_odometry, RGBDOdometryJacobianFromHybridTerm
                     (photometric + depth, Steinbruecker/Kerl-style dense RGB-D odometry)
  t_point_to_plane   Open3D's tensor projective point-to-plane ICP
                     (open3d.t.pipelines.odometry.compute_odometry_result_point_to_plane, the step of
                     rgbd_odometry_multi_scale's Method.PointToPlane) on a 3-level depth pyramid with
                     10/5/3 iterations, KinectFusion-like. Debian's Open3D 0.16.1 is built without
                     IPP, so rgbd_odometry_multi_scale itself fails (Image::FilterBilateral, and
                     RGBToGray for Method.Hybrid, are "not implemented" on the CPU); this script
                     builds the same pyramid itself (2x subsampling; for the normal map, 4 passes of
                     a 3x3 depth-gated mean instead of the bilateral filter: with 1 pass the noisy
                     normals bias a 1 cm motion by 8 mm, with 4 passes by 1.4 mm) and runs
                     Open3D's step.
  icp_point_to_plane open3d.pipelines.registration.registration_icp, point-to-plane, on
                     voxel-downsampled clouds (2 cm) with KD-tree normals
Every method is frame-to-frame: source = frame k, target = frame k-1. Open3D returns the transform
that maps source points into the target frame, i.e. T_{k-1,k} (points of k into k-1), so the
camera pose chains as T_W_k = T_W_{k-1} T_{k-1,k}. --check-direction N verifies that convention on
a known motion: frame N (the first frame within N that moved 2 cm or turned 2 degrees)
aligned onto frame 0 must match the ground truth's T_W_0^-1 T_W_N far
better than its inverse; it exits non-zero when it does not.

The trajectory is written in TUM format (stamp tx ty tz qx qy qz qw), starting at the identity
(the evaluator aligns rigidly). Timing per frame (ms, wall clock, perf_counter): "prep" = building
Open3D's input from the decoded images (RGBD image / point cloud + normals), "odometry" = the
odometry call, "total" = both; PNG decoding is not timed. OMP_NUM_THREADS defaults to 1 (set it
before running to change that) so the comparison with our single-threaded tracker is like for like.
"""
import argparse
import json
import math
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import open3d as o3d  # noqa: E402

from tum_trajectory import read_tum_trajectory  # noqa: E402

METHODS = ("legacy_hybrid", "t_point_to_plane", "icp_point_to_plane")


def read_list(path):
    """TUM list file -> [(stamp, relative path)]."""
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split()
            rows.append((float(parts[0]), parts[1]))
    return rows


def quaternion_from_rotation(R):
    """Rotation matrix -> (qx, qy, qz, qw), qw >= 0 (Shepperd's method)."""
    tr = np.trace(R)
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2]) * 2
        q = [0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s, (R[2, 1] - R[1, 2]) / s]
    elif R[1, 1] > R[2, 2]:
        s = math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2]) * 2
        q = [(R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s, (R[0, 2] - R[2, 0]) / s]
    else:
        s = math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1]) * 2
        q = [(R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s, (R[1, 0] - R[0, 1]) / s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return q if q[3] >= 0 else -q


def orthonormalize(T):
    U, _, Vt = np.linalg.svd(T[:3, :3])
    R = U @ Vt
    if np.linalg.det(R) < 0:
        U[:, -1] *= -1
        R = U @ Vt
    out = T.copy()
    out[:3, :3] = R
    return out


def associate(depth_rows, rgb_rows, max_difference=0.02):
    """Pairs every depth frame with the nearest-stamped colour frame within max_difference s."""
    rgb_stamps = np.array([s for s, _ in rgb_rows])
    pairs = []
    for stamp, depth_path in depth_rows:
        i = int(np.argmin(np.abs(rgb_stamps - stamp)))
        if abs(rgb_stamps[i] - stamp) <= max_difference:
            pairs.append((stamp, depth_path, rgb_rows[i][1]))
    return pairs


def motion_error(A, B):
    """(translation error m, rotation error rad) between two relative motions."""
    E = np.linalg.inv(A) @ B
    angle = math.acos(max(-1.0, min(1.0, (np.trace(E[:3, :3]) - 1) / 2)))
    return float(np.linalg.norm(E[:3, 3])), angle


class Odometry:
    """One method's per-frame preparation and frame-to-frame alignment."""

    def __init__(self, method, args):
        self.method = method
        self.args = args
        w, h = args.width, args.height
        self.intrinsic = o3d.camera.PinholeCameraIntrinsic(w, h, args.fx, args.fy, args.cx, args.cy)
        K = np.array([[args.fx, 0, args.cx], [0, args.fy, args.cy], [0, 0, 1]], dtype=np.float64)
        self.K_tensor = o3d.core.Tensor(K)
        if method == "legacy_hybrid":
            self.jacobian = o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm()
            # Open3D defaults except the depth range (our sequences reach 4.5 m).
            self.option = o3d.pipelines.odometry.OdometryOption(depth_max=args.depth_max)
        elif method == "t_point_to_plane":
            # rgbd_odometry_multi_scale's defaults: 3 levels, 10/5/3 iterations (fine to coarse),
            # depth_outlier_trunc 0.07 m, depth_huber_delta 0.05 m.
            self.iterations = [10, 5, 3]
            self.level_K = []
            for level in range(len(self.iterations)):
                f = 0.5 ** level
                # Subsampling pixel (2u, 2v) -> u: the principal point scales as (c) / 2.
                K_l = np.array([[args.fx * f, 0, args.cx * f], [0, args.fy * f, args.cy * f],
                                [0, 0, 1]], dtype=np.float64)
                self.level_K.append(o3d.core.Tensor(K_l))
        elif method == "icp_point_to_plane":
            self.voxel = args.voxel
            self.criteria = o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=30)
            self.estimation = o3d.pipelines.registration.TransformationEstimationPointToPlane()
        else:
            raise ValueError("unknown method %s (one of %s)" % (method, ", ".join(METHODS)))

    def load(self, seq, depth_path, rgb_path):
        """Decodes the PNGs (not timed)."""
        depth = o3d.io.read_image(os.path.join(seq, depth_path))
        color = o3d.io.read_image(os.path.join(seq, rgb_path))
        return color, depth

    def prepare(self, color, depth):
        a = self.args
        if self.method == "legacy_hybrid":
            return o3d.geometry.RGBDImage.create_from_color_and_depth(
                color, depth, depth_scale=a.depth_scale, depth_trunc=a.depth_max,
                convert_rgb_to_intensity=True)
        if self.method == "t_point_to_plane":
            z = np.asarray(depth, dtype=np.float32) / np.float32(a.depth_scale)
            z[(z <= 0) | (z > a.depth_max)] = np.nan
            levels = []
            for level, K_l in enumerate(self.level_K):
                if level > 0:
                    z = np.ascontiguousarray(z[::2, ::2])
                vertex = o3d.t.geometry.Image(o3d.core.Tensor(z[:, :, None])).create_vertex_map(
                    K_l, float("nan"))
                smooth = z
                for _ in range(a.smooth_passes):
                    smooth = gated_mean(smooth)
                smooth = o3d.t.geometry.Image(o3d.core.Tensor(smooth[:, :, None]))
                normal = smooth.create_vertex_map(K_l, float("nan")).create_normal_map(float("nan"))
                levels.append((vertex, normal))
            return levels
        cloud = o3d.geometry.PointCloud.create_from_depth_image(
            depth, self.intrinsic, depth_scale=a.depth_scale, depth_trunc=a.depth_max)
        cloud = cloud.voxel_down_sample(self.voxel)
        cloud.estimate_normals(
            o3d.geometry.KDTreeSearchParamHybrid(radius=2.5 * self.voxel, max_nn=30))
        return cloud

    def align(self, source, target, init):
        """Returns (ok, T_target_source)."""
        a = self.args
        if self.method == "legacy_hybrid":
            ok, T, _ = o3d.pipelines.odometry.compute_rgbd_odometry(
                source, target, self.intrinsic, init, self.jacobian, self.option)
            return bool(ok), np.asarray(T)
        if self.method == "t_point_to_plane":
            T = o3d.core.Tensor(init)
            fitness = 0.0
            try:
                for level in reversed(range(len(self.level_K))):  # coarse to fine
                    source_vertex = source[level][0]
                    target_vertex, target_normal = target[level]
                    for _ in range(self.iterations[level]):
                        step = o3d.t.pipelines.odometry.compute_odometry_result_point_to_plane(
                            source_vertex.as_tensor(), target_vertex.as_tensor(),
                            target_normal.as_tensor(), self.level_K[level], T, 0.07, 0.05)
                        T = step.transformation.matmul(T)  # as rgbd_odometry_multi_scale does
                        fitness = step.fitness
            except RuntimeError:
                # "Singular 6x6 linear system detected, tracking failed": no correspondences left
                # (large steps between sub-sampled frames); a failed frame, as Open3D reports it.
                return False, init
            T = T.numpy()
            return bool(np.all(np.isfinite(T)) and fitness > 0), T
        try:
            result = o3d.pipelines.registration.registration_icp(
                source, target, 2.0 * self.voxel, init, self.estimation, self.criteria)
        except RuntimeError:
            # An empty target (a frame without valid depth within depth_max) has no normals.
            return False, init
        return bool(result.fitness > 0.3), np.asarray(result.transformation)


def gated_mean(z, gate=0.03):
    """3x3 mean of the valid depths within gate (m) of the centre (NaN stays NaN): the cheap
    stand-in for Open3D's bilateral filter before its normal map."""
    h, w = z.shape
    pad = np.pad(z, 1, constant_values=np.nan)
    total = np.zeros_like(z)
    count = np.zeros_like(z)
    for dv in range(3):
        for du in range(3):
            n = pad[dv:dv + h, du:du + w]
            ok = np.abs(n - z) < gate  # False for NaN
            total += np.where(ok, n, 0)
            count += ok
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / count, np.nan).astype(np.float32)


def check_direction(odo, frames, args):
    """Known motion: frame N (source) aligned onto frame 0 (target) from the identity must give the
    ground truth's T_0_N = T_W_0^-1 T_W_N (points of N into 0), not its inverse. Returns 0 when it
    does."""
    gt = read_tum_trajectory(os.path.join(args.seq, "groundtruth.txt"))
    gt_stamps = np.array([s for s, _ in gt])
    i0 = int(np.argmin(np.abs(gt_stamps - frames[0][0])))
    # The first frame N <= check_direction that has moved 2 cm or turned 2 degrees: big enough to
    # tell T_0_N from its inverse, small enough for every method to converge from the identity.
    for n in range(1, min(args.check_direction, len(frames) - 1) + 1):
        i1 = int(np.argmin(np.abs(gt_stamps - frames[n][0])))
        truth = np.linalg.inv(gt[i0][1]) @ gt[i1][1]
        if np.linalg.norm(truth[:3, 3]) >= 0.02 or motion_error(np.eye(4), truth)[1] >= math.radians(2):
            break
    target = odo.prepare(*odo.load(args.seq, frames[0][1], frames[0][2]))
    source = odo.prepare(*odo.load(args.seq, frames[n][1], frames[n][2]))
    ok, T = odo.align(source, target, np.eye(4))
    direct_t, direct_r = motion_error(truth, T)
    inverse_t, inverse_r = motion_error(truth, np.linalg.inv(T))
    good = ok and direct_t < 0.5 * inverse_t and direct_t < 0.5 * np.linalg.norm(truth[:3, 3])
    print("direction_check %s %s: frames 0..%d, true motion %.4f m; error read as T_0_N %.4f m "
          "%.2f deg, read as its inverse %.4f m %.2f deg"
          % (args.method, "ok" if good else "FAILED", n, np.linalg.norm(truth[:3, 3]), direct_t,
             math.degrees(direct_r), inverse_t, math.degrees(inverse_r)))
    return 0 if good else 1


def percentile(values, q):
    v = sorted(values)
    return v[int(round(q * (len(v) - 1)))]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--seq", required=True)
    p.add_argument("--method", required=True, choices=METHODS)
    p.add_argument("--out", required=True)
    p.add_argument("--timing")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=480)
    p.add_argument("--fx", type=float, default=525.0)
    p.add_argument("--fy", type=float, default=525.0)
    p.add_argument("--cx", type=float, default=319.5)
    p.add_argument("--cy", type=float, default=239.5)
    p.add_argument("--depth-scale", type=float, default=5000.0)
    p.add_argument("--depth-max", type=float, default=4.5)
    p.add_argument("--voxel", type=float, default=0.02, help="icp_point_to_plane voxel size (m)")
    p.add_argument("--smooth-passes", type=int, default=4,
                   help="t_point_to_plane: passes of the 3x3 gated mean before the normal map")
    p.add_argument("--init", choices=("constant_velocity", "identity"), default="constant_velocity")
    p.add_argument("--max-frames", type=int, default=0)
    p.add_argument("--check-direction", type=int, default=0, metavar="N",
                   help="verify the source/target convention on the first N frames, then stop")
    args = p.parse_args()

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    frames = associate(read_list(os.path.join(args.seq, "depth.txt")),
                       read_list(os.path.join(args.seq, "rgb.txt")))
    if args.max_frames > 0:
        frames = frames[: args.max_frames]
    if len(frames) < 2:
        sys.exit("open3d_odometry: fewer than 2 frames in %s" % args.seq)

    odo = Odometry(args.method, args)
    if args.check_direction > 0:
        sys.exit(check_direction(odo, frames, args))
    poses = [np.eye(4)]
    motions = []
    prep_ms, odo_ms, total_ms = [], [], []
    failures = 0
    velocity = np.eye(4)
    previous = None
    for k, (stamp, depth_path, rgb_path) in enumerate(frames):
        color, depth = odo.load(args.seq, depth_path, rgb_path)
        t0 = time.perf_counter()
        current = odo.prepare(color, depth)
        t1 = time.perf_counter()
        if previous is not None:
            init = velocity if args.init == "constant_velocity" else np.eye(4)
            ok, T = odo.align(current, previous, init)
            t2 = time.perf_counter()
            if not ok:
                failures += 1
                T = init  # keep the prediction for a failed frame
            T = orthonormalize(T)
            motions.append(T)
            poses.append(orthonormalize(poses[-1] @ T))
            velocity = T
            prep_ms.append((t1 - t0) * 1e3)
            odo_ms.append((t2 - t1) * 1e3)
            total_ms.append((t2 - t0) * 1e3)
        previous = current

    with open(args.out, "w") as f:
        f.write("# open3d %s %s, frame-to-frame, T_W_C (first frame = identity)\n"
                % (o3d.__version__, args.method))
        for (stamp, _, _), T in zip(frames, poses):
            q = quaternion_from_rotation(T[:3, :3])
            t = T[:3, 3]
            f.write("%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n" % (stamp, t[0], t[1], t[2], *q))

    def stats(values):
        return {"median_ms": percentile(values, 0.5), "p95_ms": percentile(values, 0.95),
                "max_ms": max(values)}

    timing = {"method": args.method, "open3d": o3d.__version__, "frames": len(frames),
              "failures": failures, "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
              "stages": {"prep": stats(prep_ms), "odometry": stats(odo_ms),
                         "total": stats(total_ms)}}
    if args.timing:
        with open(args.timing, "w") as f:
            json.dump(timing, f, indent=1)
    print("open3d %s: %d frames, %d failed, total median %.1f ms, p95 %.1f ms"
          % (args.method, len(frames), failures, timing["stages"]["total"]["median_ms"],
             timing["stages"]["total"]["p95_ms"]))


if __name__ == "__main__":
    main()
