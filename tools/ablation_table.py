#!/usr/bin/python3
"""The ablation table and the APE-over-time figures of bench/eval_ablation.sh.

Usage: ablation_table.py RESULTS_DIR SIM_DIR OUT_DIR [--runs RUNS_DIR]

RESULTS_DIR/<course>/<row>.report.json (drover run's report.json: "ape" is the translation APE after an SE(3)
alignment, as evo_ape) and <row>.course.json (tools/course_report.py: end drift with the first pose aligned).
Writes OUT_DIR/ablation.md: per course one table, rows as run, columns the paper's Table 4 (max, min, std, median,
mean, rmse of the translation APE [m]) plus the drift [% of path] and the end-point gap [m] (closed courses: the
distance between the estimate's first and last pose; else the end error). With the runs' trajectories (RUNS_DIR,
default out/ablation) and the courses' ground truth (SIM_DIR/<course>-cam), OUT_DIR/ablation_ape_<course>.png:
the APE over time of the lvi-sam and drover rows on one figure (the paper's Fig. 11).
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from course_report import gt_at, load_tum  # noqa: E402

ROW_ORDER = ["lis", "vis", "lvi-sam", "drover", "drover+superpoint"]
STATS = ["max", "min", "std", "median", "mean", "rmse"]


def ape_of(report):
    ape = report.get("ape") or report.get("vis", {}).get("ape")
    return ape if ape and "rmse" in ape else None


def umeyama_se3(src, dst):
    """R, t minimising |dst - (R src + t)| (Umeyama 1991, no scale), points as rows."""
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    U, _, Vt = np.linalg.svd((dst - md).T @ (src - ms))
    S = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        S[2, 2] = -1
    R = U @ S @ Vt
    return R, md - R @ ms


def ape_over_time(sim_dir, run_dir, origin=False):
    """Translation error over time after an SE(3) alignment, or the first pose's (origin) on a straight course."""
    gt_t, gt = load_tum(os.path.join(sim_dir, "groundtruth.txt"))
    est_t, est = load_tum(os.path.join(run_dir, "trajectory.tum"))
    t, p, g = [], [], []
    for ti, T in zip(est_t, est):
        G = gt_at(gt_t, gt, ti)
        if G is not None:
            if not t:
                first = G @ np.linalg.inv(T)
            t.append(ti * 1e-9)
            p.append(T[:3, 3])
            g.append(G[:3, 3])
    if len(t) < 3:
        return None
    p, g = np.array(p), np.array(g)
    R, tr = (first[:3, :3], first[:3, 3]) if origin else umeyama_se3(p, g)
    return np.array(t) - t[0], np.linalg.norm((p @ R.T + tr) - g, axis=1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("results")
    ap.add_argument("sim")
    ap.add_argument("out")
    ap.add_argument("--runs", default=os.path.join(os.environ.get("DROVER_OUT", "out"), "ablation"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    lines = []
    for course_dir in sorted(glob.glob(os.path.join(a.results, "*"))):
        course = os.path.basename(course_dir)
        rows = sorted({os.path.basename(p).split(".")[0] for p in glob.glob(os.path.join(course_dir, "*.report.json"))},
                      key=lambda r: (ROW_ORDER.index(r) if r in ROW_ORDER else len(ROW_ORDER), r))
        if not rows:
            continue
        footnote = False
        lines += [f"### {course}", "",
                  "| run | " + " | ".join(f"APE {s} [m]" for s in STATS) + " | drift [% of path] | end-point gap [m] |",
                  "|---" * (len(STATS) + 3) + "|"]
        for row in rows:
            report = json.load(open(os.path.join(course_dir, f"{row}.report.json")))
            course_json = json.load(open(os.path.join(course_dir, f"{row}.course.json")))
            ape, mark = ape_of(report), ""
            if ape is None and "ape_first_pose_aligned_m" in course_json:
                ape, mark = course_json["ape_first_pose_aligned_m"], " †"
                footnote = True
            cells = [f"{ape[s]:.3f}{mark}" if ape else "-" for s in STATS]
            closed = course.startswith("farm")
            gap = course_json["start_end_m"] if closed else course_json["end_error_m"]
            name = row.replace("drover-", "drover without ", 1).replace("drover+", "drover with ", 1)
            lines.append(f"| {name} | " + " | ".join(cells) + f" | {course_json['drift_percent']:.2f} | {gap:.3f} |")
        if footnote:
            lines += ["", "† first-pose aligned (evo's --align_origin): the course is a straight line, on which an SE(3) "
                      "alignment is undetermined."]
        lines.append("")
        curves = {}
        for row in ("lvi-sam", "drover"):
            run = os.path.join(a.runs, course, row)
            if os.path.isfile(os.path.join(run, "trajectory.tum")):
                c = ape_over_time(os.path.join(a.sim, f"{course}-cam"), run, origin=footnote)
                if c is not None:
                    curves[row] = c
        if curves:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            fig, ax = plt.subplots(figsize=(8, 3.2))
            for row, (t, e) in curves.items():
                ax.plot(t, e, label=f"{row} (rmse {np.sqrt(np.mean(e ** 2)):.3f} m)")
            ax.set_xlabel("time [s]")
            ax.set_ylabel("translation APE [m]")
            ax.set_title(f"{course}: APE over time ({'first-pose' if footnote else 'SE(3)'}-aligned)")
            ax.legend()
            fig.tight_layout()
            path = os.path.join(a.out, f"ablation_ape_{course}.png")
            fig.savefig(path, dpi=110)
            lines.append(f"![APE over time, {course}](ablation_ape_{course}.png)")
            lines.append("")
    with open(os.path.join(a.out, "ablation.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
