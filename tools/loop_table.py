#!/usr/bin/env python3
"""Loop-closure table from bench/eval_loops.sh's outputs: for each course, <course>_{loop,noloop}_report.json
(drover run's report.json) and <course>_{loop,noloop}.json (tools/course_report.py). Prints Markdown."""
import glob
import json
import os
import sys


def load(path):
    with open(path) as f:
        return json.load(f)


def main(folder):
    rows = ["| course | APE rmse no loops / loops [m] | start-end gap no loops / loops [m] | end error no loops / "
            "loops [m] | loops accepted / verified | precision | recall | narrowed = full shift | loop stage mean "
            "[ms/sweep] | real-time factor |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for rep in sorted(glob.glob(os.path.join(folder, "*_loop_report.json"))):
        course = os.path.basename(rep)[: -len("_loop_report.json")]
        lr, nr = load(rep), load(os.path.join(folder, course + "_noloop_report.json"))
        lc, nc = load(os.path.join(folder, course + "_loop.json")), load(os.path.join(folder, course + "_noloop.json"))
        lp = lr["loops"]
        rows.append(
            f"| {course} | {nr['ape']['rmse']:.3f} / {lr['ape']['rmse']:.3f} | "
            f"{nc['start_end_m']:.3f} / {lc['start_end_m']:.3f} | "
            f"{nc['end_error_m']:.3f} / {lc['end_error_m']:.3f} | {lp['accepted']} / {lp['verified']} | "
            f"{lp.get('precision', float('nan')):.3f} | {lp.get('recall', float('nan')):.3f} | "
            f"{lp.get('narrowed_equals_full_shift', float('nan')):.3f} | {lr['timings']['loop']['mean_ms']:.2f} | "
            f"{lr['real_time_factor']:.2f} |")
    print("\n".join(rows))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/out/loops")
