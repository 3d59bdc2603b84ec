#!/usr/bin/python3
"""Plots element-quality histograms (write_quality_histograms_csv's CSV) to a PNG, like the paper's Figure 6.

Usage: plot_quality.py HIST.csv OUT.png [--title T]

The CSV has columns bin_low,bin_high,<label>_meccano,<label>_equilateral for each label (for example
before_smoothing, after_smoothing). The left panel shows the mean ratio against the meccano counterpart
(the paper's measure), the right one the mean ratio against the equilateral tet; each label's counts
are bars side by side within every bin.
Needs Debian's python3-matplotlib (installed by scripts/setup.sh); runs with /usr/bin/python3.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

MEASURES = (("meccano", "mean ratio against the meccano counterpart"),
            ("equilateral", "mean ratio against the equilateral tet"))


def read_histograms(path):
    """Bin edges and {label: {measure: counts}} from the CSV."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], np.array(rows[1:], dtype=float)
    if header[:2] != ["bin_low", "bin_high"] or len(header) % 2 or len(header) < 4 or not len(body):
        raise SystemExit(f"{path}: not a quality histogram CSV (header {','.join(header)})")
    histograms = {}
    for column, name in enumerate(header[2:], start=2):
        label, _, measure = name.rpartition("_")
        if measure not in dict(MEASURES):
            raise SystemExit(f"{path}: column '{name}' does not end in _meccano or _equilateral")
        histograms.setdefault(label, {})[measure] = body[:, column]
    for label, measures in histograms.items():
        if len(measures) != len(MEASURES):
            raise SystemExit(f"{path}: label '{label}' lacks a _meccano or _equilateral column")
    return body[:, 0], body[:, 1], histograms


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    low, high, histograms = read_histograms(args.csv)
    width = (high - low) / len(histograms)
    figure, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for axis, (measure, description) in zip(axes, MEASURES):
        for i, (label, counts) in enumerate(histograms.items()):
            axis.bar(low + i * width, counts[measure], width=width, align="edge", label=label.replace("_", " "))
        axis.set_xlim(0, 1)
        axis.set_xlabel(f"q, {description}")
        axis.grid(axis="y", alpha=0.3)
    axes[0].set_ylabel("tets")
    axes[0].legend()
    if args.title:
        figure.suptitle(args.title)
    figure.tight_layout()
    figure.savefig(args.png, dpi=120)


if __name__ == "__main__":
    main()
