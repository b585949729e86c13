#!/usr/bin/env python3
"""Plots of a `rovo eval` report folder (eval/report.h layout), written to <report>/plots/*.png.

  trajectories.png      top view (x, y in the ground-truth world) of ground truth and every run,
                        after SE(3) alignment; colours as the paper's Fig. 5: black GT, red GTExt,
                        blue OnlineExt, green NoisyExt
  extrinsics.png        roll / pitch / yaw of cam_i relative to cam 0 (in rig axes) per frame (OnlineExt runs),
                        ground truth dotted (the paper's Fig. 8)
  frames.png            per-frame inlier ratio and mean angular reprojection error of inliers
  error_along_path.png  translation error after alignment against distance travelled

Usage: plot_report.py REPORT_DIR. Exit status 3 when matplotlib is missing.
"""
import csv
import json
import math
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # Tick labels in plain numbers: no "-1.799e2" offset above an axis of values near -180.
    matplotlib.rcParams["axes.formatter.useoffset"] = False
except ImportError:
    sys.stderr.write("plot_report.py: matplotlib is not installed\n")
    sys.exit(3)

MODE_STYLE = {
    "gt": ("tab:red", "GTExt"),
    "online": ("tab:blue", "OnlineExt"),
    "noisy": ("tab:green", "NoisyExt"),
}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def column(rows, key, cast=float):
    return [cast(r[key]) for r in rows]


def unwrap_deg(values):
    out = []
    offset = 0.0
    for i, v in enumerate(values):
        if i:
            step = v + offset - out[-1]
            if step > 180.0:
                offset -= 360.0
            elif step < -180.0:
                offset += 360.0
        out.append(v + offset)
    return out


def style(run):
    return MODE_STYLE.get(run["mode"], ("tab:gray", run["mode"]))


def save(fig, path):
    fig.tight_layout()
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=90)
    plt.close(fig)
    os.replace(tmp, path)


def legend_once(ax):
    handles, labels = ax.get_legend_handles_labels()
    seen = {}
    for h, l in zip(handles, labels):
        seen.setdefault(l, h)
    if seen:
        ax.legend(list(seen.values()), list(seen.keys()), fontsize=8)


def plot_trajectories(report, runs, out):
    gt = read_csv(os.path.join(report, "groundtruth.csv"))
    fig, ax = plt.subplots(figsize=(7, 6))
    # Draw noisy first so the better runs stay visible on top.
    order = sorted(runs, key=lambda r: {"noisy": 0, "online": 1, "gt": 2}.get(r["mode"], 3))
    for run in order:
        rows = read_csv(os.path.join(report, run["label"], "errors.csv"))
        if not rows:
            continue
        color, name = style(run)
        ax.plot(column(rows, "est_x"), column(rows, "est_y"), color=color, lw=1.0, label=name, alpha=0.8)
    ax.plot(column(gt, "x"), column(gt, "y"), color="black", lw=1.5, ls="--", label="ground truth")
    ax.set_xlabel("x [m] (world)")
    ax.set_ylabel("y [m] (world)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("Trajectories from above (SE(3)-aligned)")
    legend_once(ax)
    ax.grid(alpha=0.3)
    save(fig, os.path.join(out, "trajectories.png"))


def plot_extrinsics(report, runs, out):
    online = [r for r in runs if r["mode"] == "online"] or [r for r in runs if r["mode"] == "noisy"]
    data = []
    for run in online:
        rows = read_csv(os.path.join(report, run["label"], "extrinsic_errors.csv"))
        if rows:
            data.append((run, rows))
    if not data:
        return
    cameras = sorted({int(r["camera"]) for _, rows in data for r in rows})
    fig, axes = plt.subplots(len(cameras), 3, figsize=(11, 2.4 * len(cameras)), squeeze=False)
    for ci, cam in enumerate(cameras):
        for ai, angle in enumerate(("roll", "pitch", "yaw")):
            ax = axes[ci][ai]
            gt_drawn = False
            for run, rows in data:
                cam_rows = [r for r in rows if int(r["camera"]) == cam]
                frames = column(cam_rows, "frame", int)
                color, name = style(run)
                gt_values = unwrap_deg(column(cam_rows, angle + "_gt_deg"))
                # Each estimate within +-180 deg of its ground truth (the same angle, drawn next to it).
                est_values = [e + 360.0 * round((g - e) / 360.0)
                              for e, g in zip(column(cam_rows, angle + "_est_deg"), gt_values)]
                ax.plot(frames, est_values, color=color, lw=1.0, label=name, alpha=0.8)
                if not gt_drawn:
                    ax.plot(frames, gt_values, color="black", ls=":", lw=1.5, label="ground truth")
                    gt_drawn = True
            ax.set_title("cam%d rel. cam0 (rig axes): %s [deg]" % (cam, angle), fontsize=9)
            ax.set_xlabel("frame", fontsize=8)
            ax.grid(alpha=0.3)
            if ci == 0 and ai == 0:
                legend_once(ax)
    save(fig, os.path.join(out, "extrinsics.png"))


def plot_frames(report, runs, out):
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for run in runs:
        rows = [r for r in read_csv(os.path.join(report, run["label"], "frames.csv")) if r["status"] == "ok"]
        if not rows:
            continue
        color, name = style(run)
        frames = column(rows, "frame", int)
        ax1.plot(frames, [100.0 * v for v in column(rows, "inlier_ratio")], color=color, lw=0.8, label=name, alpha=0.8)
        ax2.plot(frames, column(rows, "mean_reproj_error_deg"), color=color, lw=0.8, label=name, alpha=0.8)
    ax1.set_ylabel("inlier ratio [%]")
    ax2.set_ylabel("mean reproj. error [deg]")
    ax2.set_xlabel("frame")
    ax1.set_title("Per-frame multi-view P3P RANSAC inlier ratio and angular reprojection error (status ok)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    legend_once(ax1)
    save(fig, os.path.join(out, "frames.png"))


def plot_error_along_path(report, runs, out):
    fig, ax = plt.subplots(figsize=(9, 4))
    for run in runs:
        rows = read_csv(os.path.join(report, run["label"], "errors.csv"))
        if not rows:
            continue
        distance = [0.0]
        for a, b in zip(rows[:-1], rows[1:]):
            distance.append(distance[-1] + math.dist((float(a["gt_x"]), float(a["gt_y"]), float(a["gt_z"])),
                                                     (float(b["gt_x"]), float(b["gt_y"]), float(b["gt_z"]))))
        color, name = style(run)
        ax.plot(distance, column(rows, "error_m"), color=color, lw=1.0, label=name, alpha=0.8)
    ax.set_xlabel("distance along the ground-truth path [m]")
    ax.set_ylabel("translation error [m]")
    ax.set_yscale("log")
    ax.set_title("Translation error along the path (after SE(3) alignment)")
    ax.grid(alpha=0.3, which="both")
    legend_once(ax)
    save(fig, os.path.join(out, "error_along_path.png"))


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: plot_report.py REPORT_DIR\n")
        return 2
    report = sys.argv[1]
    with open(os.path.join(report, "metrics.json")) as f:
        runs = json.load(f)["runs"]
    out = os.path.join(report, "plots")
    os.makedirs(out, exist_ok=True)
    plot_trajectories(report, runs, out)
    plot_extrinsics(report, runs, out)
    plot_frames(report, runs, out)
    plot_error_along_path(report, runs, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
