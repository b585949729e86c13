#!/usr/bin/env python3
"""CDF of the extrinsic error over perturbation draws, from a `rovo study calibration` folder.

Reads <dir>/calibration.csv and <dir>/calibration.json; writes <dir>/cdf.png: the fraction of draws
whose extrinsic error (largest over cameras i >= 1, degrees, log scale) is at most x, before any
calibration, after the start-up calibration, at frame 100 and at the end of the run (when the study
ran the VO), with the convergence bound as a vertical line.

Usage: plot_calibration.py DIR. Exit status 3 when matplotlib is missing.
"""
import csv
import json
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("plot_calibration.py: matplotlib is not installed\n")
    sys.exit(3)


def main(folder):
    with open(os.path.join(folder, "calibration.json")) as f:
        meta = json.load(f)
    with open(os.path.join(folder, "calibration.csv")) as f:
        rows = list(csv.DictReader(f))
    series = [("before_deg", "drawn (before)", "0.6"), ("startup_deg", "after start-up", "tab:orange"),
              ("at100_deg", "frame 100", "tab:green"), ("end_deg", "end of run", "tab:blue")]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for key, label, colour in series:
        values = sorted(max(float(r[key]), 1e-4) for r in rows if float(r[key]) >= 0.0)
        if not values:
            continue
        ys = [(i + 1) / len(values) for i in range(len(values))]
        ax.step(values, ys, where="post", label="%s (%d)" % (label, len(values)), color=colour)
    ax.axvline(meta["converged_below_deg"], color="k", linestyle=":", label="bound %.2g deg" % meta["converged_below_deg"])
    ax.set_xscale("log")
    ax.set_xlabel("extrinsic error, largest camera vs camera 0 (deg)")
    ax.set_ylabel("fraction of draws")
    ax.set_ylim(0, 1.02)
    ax.set_title("%s: %d/%d draws converged (sigma %.1f deg)" % (
        os.path.basename(os.path.normpath(meta["dataset"])), meta["converged"], meta["draws"], meta["sigma_deg"]))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    tmp = os.path.join(folder, ".cdf.png.tmp")
    fig.savefig(tmp, dpi=110, format="png")
    os.replace(tmp, os.path.join(folder, "cdf.png"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        sys.exit(2)
    main(sys.argv[1])
