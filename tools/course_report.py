#!/usr/bin/python3
"""Accuracy of a `drover run` on a simulated course, overall and per labelled segment.

Usage: course_report.py DATASET_DIR RUN_DIR [--json OUT.json] [--trajectory trajectory_vis.tum]

DATASET_DIR is a `drover sim` folder (groundtruth.txt: T_world_imu, TUM; scenario.json: path length and labelled
segments); RUN_DIR holds the run's trajectory.tum (T_world_imu, one pose per sweep). The estimate is put in the
ground truth's frame by its first pose (no fitting, so drift shows in full). Estimate stamps that are not ground-truth
stamps (camera frames, an estimated time offset) get the ground truth interpolated (translation linearly, rotation of
the nearer sample) when within one ground-truth step. Figures:
  end_error_m        |p_est(end) - p_gt(end)| after that first-pose alignment
  drift_percent      end_error_m / ground-truth path length * 100
  start_end_m        |p_est(end) - p_est(start)| (closed courses end where they start)
  segments[]         per labelled segment: relative pose error between its first and last sweep,
                     translation as % of the segment's path length and rotation in degrees
                     (injected faults, scenario.json "faults", as segments "fault:KIND" from the fault's start to
                     10 s after its end: what the fault and the re-joining cost)
Deliberately independent of Drover's C++ evaluator (numpy only), so the two can check each other.
"""
import argparse
import json
import sys

import numpy as np


def load_tum(path):
    times, poses = [], []
    with open(path) as f:
        for line in f:
            if not line.strip() or line.startswith("#"):
                continue
            v = [float(x) for x in line.split()]
            times.append(round(v[0] * 1e9))
            poses.append(pose_matrix(v[1:4], v[4:8]))
    return np.array(times, dtype=np.int64), poses


def pose_matrix(t, q_xyzw):
    x, y, z, w = q_xyzw
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = t
    return T


def angle_deg(R):
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))))


def path_length(poses):
    p = np.array([T[:3, 3] for T in poses])
    return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1))) if len(p) > 1 else 0.0


def gt_at(gt_times, gt, t):
    """Ground-truth pose at t [ns]: exact, or interpolated between two samples at most 10 ms apart."""
    k = int(np.searchsorted(gt_times, t))
    if k < len(gt_times) and gt_times[k] == t:
        return gt[k]
    if k == 0 or k == len(gt_times) or gt_times[k] - gt_times[k - 1] > 10_000_000:
        return None
    a, b = gt[k - 1], gt[k]
    s = (t - gt_times[k - 1]) / (gt_times[k] - gt_times[k - 1])
    T = (a if s < 0.5 else b).copy()
    T[:3, 3] = (1 - s) * a[:3, 3] + s * b[:3, 3]
    return T


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dataset")
    ap.add_argument("run")
    ap.add_argument("--json")
    ap.add_argument("--trajectory", default="trajectory.tum", help="file in RUN_DIR (trajectory_vis.tum: the VIS)")
    a = ap.parse_args()
    gt_t, gt = load_tum(f"{a.dataset}/groundtruth.txt")
    est_t, est = load_tum(f"{a.run}/{a.trajectory}")
    with open(f"{a.dataset}/scenario.json") as f:
        scenario = json.load(f)
    gt_times = np.array(gt_t, dtype=np.int64)
    pairs, gt_m = [], []
    for i, t in enumerate(est_t):
        G = gt_at(gt_times, gt, t)
        if G is not None:
            pairs.append(i)
            gt_m.append(G)
    if len(pairs) < 2:
        sys.exit(f"error: fewer than 2 estimate poses match ground-truth stamps in {a.run}")
    est_m = [est[i] for i in pairs]
    times = np.array([est_t[i] for i in pairs])
    align = gt_m[0] @ np.linalg.inv(est_m[0])
    est_a = [align @ T for T in est_m]
    errors = np.array([np.linalg.norm(E[:3, 3] - G[:3, 3]) for E, G in zip(est_a, gt_m)])
    length = path_length(gt_m)
    out = {
        "scenario": scenario.get("scenario"),
        "sweeps": len(pairs),
        "path_length_m": length,
        "end_error_m": float(errors[-1]),
        "drift_percent": float(100 * errors[-1] / length) if length > 0 else 0.0,
        "max_error_m": float(errors.max()),
        "rmse_first_pose_aligned_m": float(np.sqrt(np.mean(errors ** 2))),
        # The translation errors' statistics after the first-pose alignment (evo's --align_origin): what an APE
        # can say of a straight course, on which an SE(3) alignment is undetermined.
        "ape_first_pose_aligned_m": {"max": float(errors.max()), "min": float(errors.min()),
                                     "std": float(errors.std()), "median": float(np.median(errors)),
                                     "mean": float(errors.mean()), "rmse": float(np.sqrt(np.mean(errors ** 2)))},
        "start_end_m": float(np.linalg.norm(est_a[-1][:3, 3] - est_a[0][:3, 3])),
        "segments": [],
    }
    # Injected faults (drover sim --fault): the window and the 10 s after it, where the failing side re-joins.
    windows = list(scenario.get("segments", []))
    for f in scenario.get("faults", []):
        windows.append({"condition": "fault:" + f["kind"], "start_ns": f["start_ns"],
                        "end_ns": f["end_ns"] + 10_000_000_000})
    for seg in windows:
        sel = np.nonzero((times >= seg["start_ns"]) & (times <= seg["end_ns"]))[0]
        if len(sel) < 2:
            continue
        i0, i1 = sel[0], sel[-1]
        rel_gt = np.linalg.inv(gt_m[i0]) @ gt_m[i1]
        rel_est = np.linalg.inv(est_a[i0]) @ est_a[i1]
        seg_len = path_length(gt_m[i0:i1 + 1])
        t_err = float(np.linalg.norm(rel_est[:3, 3] - rel_gt[:3, 3]))
        out["segments"].append({
            "condition": seg["condition"], "start_s": seg["start_ns"] * 1e-9, "end_s": seg["end_ns"] * 1e-9,
            "length_m": seg_len, "translation_error_m": t_err,
            "translation_error_percent": 100 * t_err / seg_len if seg_len > 0 else 0.0,
            "rotation_error_deg": angle_deg(rel_gt[:3, :3].T @ rel_est[:3, :3]),
        })
    print(f"{out['scenario']}: {out['sweeps']} sweeps, {length:.1f} m; end error {out['end_error_m']:.3f} m "
          f"({out['drift_percent']:.2f} %), max {out['max_error_m']:.3f} m, start-end {out['start_end_m']:.3f} m")
    for s in out["segments"]:
        print(f"  {s['condition']:>21} {s['start_s']:7.1f}-{s['end_s']:7.1f} s {s['length_m']:7.1f} m: "
              f"{s['translation_error_m']:.3f} m ({s['translation_error_percent']:.2f} %), "
              f"{s['rotation_error_deg']:.2f} deg")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=2)


if __name__ == "__main__":
    main()
