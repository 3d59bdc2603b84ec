#!/usr/bin/python3
"""Plots convergence_study's CSV files (errors against h, log-log) to a PNG.

Usage: plot_convergence.py OUT.png LABEL=STUDY.csv [LABEL=STUDY.csv ...] [--title T]

Each CSV has the columns h,tets,dofs,l2_error,h1_error,normal_error_deg,seconds (one row per level).
Left: the L2 error, middle: the H1-seminorm error, right: the largest angle between a face of S_h and
S's normal (a property of the mesh: studies on the same meshes give one curve). Each curve is labelled with its last
rate, log(e_{k-1}/e_k) / log(h_{k-1}/h_k); dotted lines show slopes 1, 2 and 3 for reference.
Needs Debian's python3-matplotlib (installed by scripts/setup.sh); runs with /usr/bin/python3.
Example: plot_convergence.py doc/figures/convergence.png P1=p1.csv P2=p2.csv
"""
import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ["h", "tets", "dofs", "l2_error", "h1_error", "normal_error_deg", "seconds"]
PANELS = (("l2_error", "L2 error  ||u - u_h||"), ("h1_error", "H1 error  ||grad(u - u_h)||"),
          ("normal_error_deg", "max normal angle (degrees)"))


def read_study(path):
    """{column: [values]} of one study, checked."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != COLUMNS:
        raise SystemExit(f"{path}: not a convergence_study CSV (header {','.join(rows[0]) if rows else 'missing'})")
    if len(rows) < 2:
        raise SystemExit(f"{path}: no levels")
    try:
        values = [[float(v) for v in row] for row in rows[1:]]
    except ValueError as error:
        raise SystemExit(f"{path}: {error}")
    return {name: [row[i] for row in values] for i, name in enumerate(COLUMNS)}


def last_rate(h, error):
    if len(h) < 2:
        return None
    return math.log(error[-2] / error[-1]) / math.log(h[-2] / h[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("png")
    parser.add_argument("studies", nargs="+", metavar="LABEL=STUDY.csv")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    studies = []
    for item in args.studies:
        label, separator, path = item.partition("=")
        if not separator or not label or not path:
            raise SystemExit(f"'{item}': expected LABEL=STUDY.csv")
        studies.append((label, read_study(path)))

    figure, axes = plt.subplots(1, len(PANELS), figsize=(15, 4.8))
    for axis, (column, description) in zip(axes, PANELS):
        plotted = []
        for label, study in studies:
            if study[column] in plotted:
                continue  # the normal angle depends on the mesh only: one curve for degrees on the same meshes
            plotted.append(study[column])
            rate = last_rate(study["h"], study[column])
            text = f"{label}" + (f" (last rate {rate:.2f})" if rate is not None else "")
            axis.loglog(study["h"], study[column], "o-", label=text)
        # Reference slopes through the first study's coarsest point.
        h = studies[0][1]["h"]
        start = studies[0][1][column][0]
        for slope in (1, 2, 3):
            axis.loglog([h[0], h[-1]], [start, start * (h[-1] / h[0]) ** slope], ":", color="grey", linewidth=0.8)
            axis.annotate(f"h^{slope}", (h[-1], start * (h[-1] / h[0]) ** slope), fontsize=8, color="grey")
        axis.set_xlabel("h (longest edge)")
        axis.set_title(description)
        axis.grid(which="both", alpha=0.3)
        axis.legend(fontsize=8)
    if args.title:
        figure.suptitle(args.title)
    figure.tight_layout()
    # Atomic: a failed run leaves no half-written picture.
    temporary = f"{args.png}.tmp{os.getpid()}.png"
    try:
        figure.savefig(temporary, dpi=110)
        os.replace(temporary, args.png)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


if __name__ == "__main__":
    main()
