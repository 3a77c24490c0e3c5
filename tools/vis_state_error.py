#!/usr/bin/python3
"""The VIS's speed and forward specific-force error against a simulated course's truth, frame by frame.

Usage: vis_state_error.py DATASET_DIR RUN_DIR [--every 1.0 | --at T ...] [--acc-bias BX BY BZ] [--json OUT.json]

RUN_DIR is a `drover run` with a camera (trajectory_vis.tum and vis_frames.jsonl, whose initialised lines carry the
VIS's speed and accelerometer bias); DATASET_DIR the simulated course (groundtruth.txt, T_world_body). Where the VIS
sees no motion (a dark stretch, a blank wall) it dead-reckons on the IMU with the acceleration its state makes of the
IMU's specific force. That acceleration, in the body frame, is off the truth by
    e = (b_true - b_vis) - g (R_vis^T z - R_true^T z)     [m/s^2]
(the bias error, and gravity leaking through the attitude error): its forward component is what makes the speed run
away at constant speed, and only that sum is observable there, not the bias and the tilt apart. The true bias is
the simulator's turn-on accelerometer bias (src/sim/imu_model.hpp; its walk, ~0.002 m/s^2 over 40 s, is left out);
body = IMU frame, as on Drover's simulated ground robots. Per time: VIS speed, its error against the truth's
(central difference) [m/s], e forward / lateral / up [m/s^2], the tilt's share of e forward, the frame's features held
to the ground and whether it was a keyframe.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from course_report import load_tum  # noqa: E402

SIM_ACC_BIAS = (0.02, -0.03, 0.01)  # [m/s^2] sim::ImuModelConfig::initial_accel_bias
UP = np.array([0.0, 0.0, 1.0])


def fail(message):
    sys.exit(f"vis_state_error: {message}")


def load_frames(path):
    frames = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            try:
                j = json.loads(line)
            except json.JSONDecodeError as e:
                fail(f"{path}: line {n}: not JSON: {e}")
            if j.get("initialized") and "acc_bias" in j:
                frames.append(j)
    return frames


def true_speed(gt_times, gt, t):
    k = int(np.clip(np.searchsorted(gt_times, t), 1, len(gt_times) - 2))
    return np.linalg.norm(gt[k + 1][:3, 3] - gt[k - 1][:3, 3]) / ((gt_times[k + 1] - gt_times[k - 1]) * 1e-9)


def row(frame, vis_pose, true_pose, speed_true, acc_bias, gravity):
    tilt = gravity * (vis_pose[:3, :3].T @ UP - true_pose[:3, :3].T @ UP)
    e = (np.array(acc_bias) - np.array(frame["acc_bias"])) - tilt
    return {"t": frame["t"], "speed": frame["speed"], "speed_error": frame["speed"] - speed_true,
            "forward": e[0], "lateral": e[1], "up": e[2], "forward_from_tilt": -tilt[0],
            "on_ground": frame.get("on_ground", 0), "keyframe": bool(frame.get("keyframe", False))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset")
    ap.add_argument("run")
    ap.add_argument("--every", type=float, default=1.0, help="[s] one row per this much time")
    ap.add_argument("--at", type=float, nargs="+", help="[s] rows at these times instead")
    ap.add_argument("--acc-bias", type=float, nargs=3, default=SIM_ACC_BIAS, help="[m/s^2] the true bias")
    ap.add_argument("--gravity", type=float, default=9.81, help="[m/s^2]")
    ap.add_argument("--json", help="also write the rows here")
    a = ap.parse_args()
    paths = [os.path.join(a.dataset, "groundtruth.txt"), os.path.join(a.run, "trajectory_vis.tum"),
             os.path.join(a.run, "vis_frames.jsonl")]
    for p in paths:
        if not os.path.isfile(p):
            fail(f"{p}: no such file")
    trajectories = []
    for p in paths[:2]:
        try:
            trajectories.append(load_tum(p))
        except (ValueError, IndexError) as e:
            fail(f"{p}: not a TUM trajectory (t x y z qx qy qz qw a line): {e}")
    (gt_t, gt), (vis_t, vis) = trajectories
    frames = load_frames(paths[2])
    if not frames or len(gt_t) < 3:
        fail(f"{paths[2]}: no initialised frame with a state (or a ground truth of fewer than 3 poses)")
    stamps = np.array([round(f["t"] * 1e9) for f in frames], dtype=np.int64)
    times = a.at if a.at else np.arange(frames[0]["t"], frames[-1]["t"] + 1e-9, a.every)
    rows = []
    for t in times:
        frame = frames[int(np.argmin(np.abs(stamps - round(t * 1e9))))]
        ns = round(frame["t"] * 1e9)
        k = int(np.argmin(np.abs(vis_t - ns)))
        g = int(np.argmin(np.abs(gt_t - ns)))
        if abs(vis_t[k] - ns) > 1_000_000 or abs(gt_t[g] - ns) > 10_000_000:
            continue  # no pose of the VIS or the truth at this frame
        rows.append(row(frame, vis[k], gt[g], true_speed(gt_t, gt, ns), a.acc_bias, a.gravity))
    print("t [s]  speed, error [m/s]  specific-force error forward (tilt's share) / lateral / up [m/s^2]  ground kf")
    for r in rows:
        print(f"{r['t']:7.2f}  {r['speed']:.3f} {r['speed_error']:+.3f}  {r['forward']:+.4f}"
              f" ({r['forward_from_tilt']:+.4f}) / {r['lateral']:+.4f} / {r['up']:+.4f}"
              f"  {r['on_ground']:3d} {'k' if r['keyframe'] else '-'}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"acc_bias_true": list(a.acc_bias), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
