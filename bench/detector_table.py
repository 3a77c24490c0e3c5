#!/usr/bin/python3
"""Regenerates the detector comparison table of bench/RESULTS.md (the LVI-SAM paper's Fig. 4 argument: SuperPoint
keeps keypoints spread where corner detectors fail): keypoint count and coverage (fraction of a 16x12 grid of
cells holding a keypoint) of SuperPoint, Shi-Tomasi and ORB, with the settings of bench/detector_table.yaml, on

  - KITTI 00 and 05 image_2 (the 2 x 10 frames in ../shared/data), and their darkened copies;
  - EuRoC V1_01_easy_micro cam0 (every 5th of the 95 frames), and their darkened copies;
  - the simulator's `lighting` scenario, its dark stretch (frames darker than 15 % of the sequence's brightest mean);
  - the simulator's `white-walls` scenario (frames inside its white-walls segment, every 5th, at most 20).

Darkened = `drover features detect --darken 0.25`: exposure x 0.25 (the mean intensity becomes 25 %), shot noise
(Gaussian approximation of Poisson, 1 grey level per photo-electron: variance = signal) and Gaussian read noise of
sigma 2 grey levels, rounded and clamped to 0..255, seed 1 + image index. For darkened images the table also gives
the repeatability under noise: the same images darkened again with other noise (seed 1001 + index), and the
fraction of keypoints of the first copy with a keypoint of the second within 2 px (noise corners do not come back).

Usage: bench/detector_table.py [--drover build/apps/drover/drover] [--sim-dir /tmp] [--out table.md]
The simulated courses are generated when missing (drover sim --scenario lighting|white-walls --duration 20).
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
DETECTORS = ["superpoint", "shi-tomasi", "orb"]


def detect(drover, detector, images, darken=0.0, seed=1):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "d.json")
        cmd = [drover, "-q", "features", "detect", "--config", os.path.join(ROOT, "bench", "detector_table.yaml"),
               "--detector", detector, "--json", out, "--weights",
               os.path.join(SHARED, "models", "superpoint_v1.onnx")] + images
        if darken:
            cmd += ["--darken", str(darken), "--seed", str(seed), "--json-points"]
        subprocess.run(cmd, check=True)
        with open(out) as f:
            return json.load(f)["images"]


def repeatability(a, b, radius=2.0):
    """Mean over images of the fraction of keypoints of `a` with a keypoint of `b` within `radius` px."""
    fractions = []
    for ia, ib in zip(a, b):
        pa, pb = np.array(ia["points"]).reshape(-1, 2), np.array(ib["points"]).reshape(-1, 2)
        if len(pa) == 0 or len(pb) == 0:
            fractions.append(0.0)
            continue
        d = np.linalg.norm(pa[:, None, :] - pb[None, :, :], axis=2).min(axis=1)
        fractions.append(float(np.mean(d <= radius)))
    return sum(fractions) / len(fractions)


def simulated(drover, sim_dir, scenario):
    path = os.path.join(sim_dir, "drover_sim_" + scenario)
    if not os.path.isdir(path):
        subprocess.run([drover, "-q", "sim", "--scenario", scenario, "--duration", "20", "--out", path], check=True)
    stamps = {}
    with open(os.path.join(path, "camera", "timestamps.csv")) as f:
        for line in f:
            if line[0].isdigit():
                i, t = line.strip().split(",")
                stamps[os.path.join(path, "camera", "%06d.png" % int(i))] = int(t)
    with open(os.path.join(path, "scenario.json")) as f:
        segments = json.load(f)["segments"]
    return path, stamps, segments


def dark_frames(drover, sim_dir):
    path, stamps, _ = simulated(drover, sim_dir, "lighting")
    frames = sorted(stamps)
    means = [im["mean_intensity"] for im in detect(drover, "shi-tomasi", frames)]
    dark = [f for f, m in zip(frames, means) if m < 0.15 * max(means)]
    return dark[:: max(1, len(dark) // 20)][:20]


def white_wall_frames(drover, sim_dir):
    path, stamps, segments = simulated(drover, sim_dir, "white-walls")
    spans = [(s["start_ns"], s["end_ns"]) for s in segments if s["condition"] == "white-walls"]
    inside = [f for f in sorted(stamps) if any(a <= stamps[f] <= b for a, b in spans)]
    return inside[::5][:20]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--drover", default=os.path.join(ROOT, "build", "apps", "drover", "drover"))
    ap.add_argument("--sim-dir", default=tempfile.gettempdir())
    ap.add_argument("--out", help="also write the table to this file")
    a = ap.parse_args()
    kitti = sorted(glob.glob(os.path.join(SHARED, "data/kitti/sequences/00/image_2/*.png"))) + \
        sorted(glob.glob(os.path.join(SHARED, "data/kitti/sequences/05/image_2/*.png")))
    euroc = sorted(glob.glob(os.path.join(SHARED, "data/euroc/V1_01_easy_micro/mav0/cam0/data/*.png")))[::5]
    if not kitti or not euroc:
        sys.exit("detector_table: ../shared/data (KITTI 00/05 image_2, EuRoC V1_01_easy_micro) not found")
    sets = [("KITTI 00+05 image_2", kitti, 0.0), ("KITTI darkened", kitti, 0.25),
            ("EuRoC V1_01 cam0", euroc, 0.0), ("EuRoC darkened", euroc, 0.25),
            ("sim lighting, dark stretch", dark_frames(a.drover, a.sim_dir), 0.0),
            ("sim white-walls", white_wall_frames(a.drover, a.sim_dir), 0.0)]
    lines = ["| images (n) | mean grey | " + " | ".join(
        "%s count (min) | %s coverage | %s repeat." % (d, d, d) for d in DETECTORS) + " | SuperPoint ms |",
        "|---|---:|" + "---:|---:|---:|" * len(DETECTORS) + "---:|"]
    for name, images, darken in sets:
        cells, grey, sp_ms = [], 0.0, 0.0
        for d in DETECTORS:
            res = detect(a.drover, d, images, darken)
            counts = [r["count"] for r in res]
            cov = sum(r["coverage"] for r in res) / len(res)
            rep = "—"
            if darken:  # the same darkened images with other noise: do the keypoints come back?
                rep = "%.2f" % repeatability(res, detect(a.drover, d, images, darken, seed=1001))
            cells.append("%.0f (%d) | %.2f | %s" % (sum(counts) / len(counts), min(counts), cov, rep))
            grey = sum(r["mean_intensity"] for r in res) / len(res)
            if d == "superpoint":
                sp_ms = sum(r["ms"] for r in res) / len(res)
        lines.append("| %s (%d) | %.0f | %s | %.0f |" % (name, len(images), grey, " | ".join(cells), sp_ms))
        print(lines[-1], file=sys.stderr)
    table = "\n".join(lines) + "\n"
    print(table)
    if a.out:
        with open(a.out, "w") as f:
            f.write(table)


if __name__ == "__main__":
    main()
