#!/usr/bin/python3
"""Plot of a `drover eval` result: the error over time and the trajectory from above (x-y), coloured by error.

Usage: plot_trajectory.py DATA.json OUT.png

DATA.json is written by `drover eval ape|rpe --plot` with the keys title, unit, seconds_from_start, error,
est_x, est_y (aligned estimate at each error) and ref_x, ref_y (matched reference). Runs headless (Agg backend).
Exit codes: 0 written, 2 bad input, 3 matplotlib missing. One line on stderr says what went wrong.
"""
import json
import sys


def fail(code, message):
    print(message, file=sys.stderr)
    sys.exit(code)


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        fail(2, f"cannot read plot data {path}: {e}")
    keys = ("title", "unit", "seconds_from_start", "error", "est_x", "est_y", "ref_x", "ref_y")
    missing = [k for k in keys if k not in data]
    if missing:
        fail(2, f"plot data {path} lacks {', '.join(missing)}")
    n = len(data["error"])
    if n == 0 or any(len(data[k]) != n for k in ("seconds_from_start", "est_x", "est_y")):
        fail(2, f"plot data {path}: error, time and position lists must be non-empty and of equal length")
    return data


def statistic_lines(ax, errors):
    mean = sum(errors) / len(errors)
    ordered = sorted(errors)
    mid = len(ordered) // 2
    median = ordered[mid] if len(ordered) % 2 else 0.5 * (ordered[mid - 1] + ordered[mid])
    rmse = (sum(e * e for e in errors) / len(errors)) ** 0.5
    for value, name, style in ((rmse, "rmse", "-"), (median, "median", "--"), (mean, "mean", ":")):
        ax.axhline(value, linestyle=style, color="black", linewidth=1, label=f"{name} {value:.4g}")


def main(argv):
    if len(argv) != 3:
        fail(2, "usage: plot_trajectory.py DATA.json OUT.png")
    data = load(argv[1])
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        fail(3, f"matplotlib is not available to {sys.executable} ({e})")

    unit = data["unit"]
    errors = data["error"]
    fig, (ax_t, ax_xy) = plt.subplots(1, 2, figsize=(13, 5.5))
    fig.suptitle(data["title"].replace("\n", " "), fontsize=10)

    ax_t.plot(data["seconds_from_start"], errors, color="tab:blue", linewidth=1, label="error")
    statistic_lines(ax_t, errors)
    ax_t.set_xlabel("t - t_start [s]")
    ax_t.set_ylabel(f"error [{unit}]")
    ax_t.grid(True, alpha=0.3)
    ax_t.legend(fontsize=8)

    ax_xy.plot(data["ref_x"], data["ref_y"], "--", color="gray", linewidth=1, label="reference")
    points = ax_xy.scatter(data["est_x"], data["est_y"], c=errors, cmap="jet", s=6, label="estimate")
    fig.colorbar(points, ax=ax_xy, label=f"error [{unit}]")
    ax_xy.set_xlabel("x [m]")
    ax_xy.set_ylabel("y [m]")
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.grid(True, alpha=0.3)
    ax_xy.legend(fontsize=8)

    fig.tight_layout()
    try:
        fig.savefig(argv[2], dpi=100)
    except OSError as e:
        fail(2, f"cannot write {argv[2]}: {e}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
