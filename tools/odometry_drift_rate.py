#!/usr/bin/python3
"""How fast a run's odometry drifts per keyframe step: the numbers for loop.odometry_sigma_position / _rotation.

Usage: odometry_drift_rate.py DATASET_DIR RUN_DIR [--spans 1 10 100 300] [--json OUT.json]

RUN_DIR is a `drover run ... --no-loop` on a simulated course (DATASET_DIR, groundtruth.txt): its keyframes.tum is
compared with the ground truth over every span of N consecutive keyframes. The loop closure's pose graph models the
odometry as independent errors per keyframe step, i.e. a random walk: over N steps its error grows as
sigma_step * sqrt(N). So each span gives sigma_step = rms error over the span / sqrt(N). Short spans overstate it
(the scan matcher's error against its map does not accumulate from one keyframe to the next); the long spans are
what a loop spans, and what the graph's edges should state. Figures per span: the span's mean length [m], the rms
relative translation error [m] and rotation error [deg], and the implied per-step sigmas [m], [rad].
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from course_report import angle_deg, gt_at, load_tum  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset")
    ap.add_argument("run")
    ap.add_argument("--spans", type=int, nargs="+", default=[1, 10, 30, 100, 300])
    ap.add_argument("--json", help="also write the figures here")
    a = ap.parse_args()
    for f in (os.path.join(a.dataset, "groundtruth.txt"), os.path.join(a.run, "keyframes.tum")):
        if not os.path.isfile(f):
            sys.exit(f"odometry_drift_rate: {f}: no such file")
    loaded = []
    for f in (os.path.join(a.dataset, "groundtruth.txt"), os.path.join(a.run, "keyframes.tum")):
        try:
            loaded.append(load_tum(f))
        except (ValueError, IndexError) as e:
            sys.exit(f"odometry_drift_rate: {f}: not a TUM trajectory (t x y z qx qy qz qw a line): {e}")
    (gt_times, gt), (kf_times, kf) = loaded
    pairs = [(e, g) for t, e in zip(kf_times, kf) if (g := gt_at(gt_times, gt, t)) is not None]
    if len(pairs) < 2:
        sys.exit(f"odometry_drift_rate: {a.run}/keyframes.tum: fewer than 2 keyframes within the ground truth")
    print(f"{len(pairs)} keyframes; span [keyframes]: length, rms translation / rotation error -> per-step sigma")
    rows = []
    for n in a.spans:
        if n >= len(pairs):
            break
        et, er, length = [], [], []
        for (ei, gi), (ej, gj) in zip(pairs[:-n], pairs[n:]):
            d_est = np.linalg.inv(ei) @ ej
            d_gt = np.linalg.inv(gi) @ gj
            err = np.linalg.inv(d_gt) @ d_est
            et.append(np.linalg.norm(err[:3, 3]))
            er.append(math.radians(angle_deg(err[:3, :3])))
            length.append(np.linalg.norm(d_gt[:3, 3]))
        rt, rr = math.sqrt(np.mean(np.square(et))), math.sqrt(np.mean(np.square(er)))
        print(f"  {n:5d} ({np.mean(length):7.1f} m): {rt:.4f} m / {math.degrees(rr):.4f} deg"
              f" -> {rt / math.sqrt(n):.4f} m, {rr / math.sqrt(n):.2e} rad")
        rows.append({"keyframes": n, "length_m": float(np.mean(length)), "translation_rms_m": rt,
                     "rotation_rms_rad": rr, "sigma_position_m": rt / math.sqrt(n),
                     "sigma_rotation_rad": rr / math.sqrt(n)})
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"keyframes": len(pairs), "spans": rows}, f, indent=1)


if __name__ == "__main__":
    main()
