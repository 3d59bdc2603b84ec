#!/usr/bin/python3
"""SUS (the smoothing stage) of two builds of meccano-immerse side by side, in one run (issue 18).

    compare_sus.py BEFORE_CLI AFTER_CLI [--faults DIR] [--repeat N] [--threads T]

Cases: the cube example in the unit cube at l_r = 1/64 (the issue's), and every GOCAD TSurf fault of DIR
(default ../shared/data/faults beside the checkout; skipped if missing) in its box (bounding box + 10 % of
its largest extent E per side) at l_r = E / 50. For each case the two builds run alternately, N times each
(default 2), and the fastest smoothing of each is kept: these machines are noisy. Prints a Markdown table
of the smoothing seconds, sweeps, node updates, microseconds per node update, the speed-up, step 4 as a
whole (SUS and the improvement stage, where a build has it) and the whole insertion, and the quality of
the result of both (meccano and equilateral η min/mean, dihedral range), with the largest
difference of the η figures.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_faults import case_box, case_name, read_surface  # noqa: E402

REPOSITORY = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DIVISOR = 50


def cases(faults):
    """(name, surface argument, box text, l_r) per case."""
    yield "cube example, 1/64", os.path.join(REPOSITORY, "meshes", "cube_example.obj") + ":patch", "0,0,0,1,1,1", 1 / 64
    if not os.path.isdir(faults):
        print(f"faults: {faults} not found, skipped", file=sys.stderr)
        return
    for file in sorted(os.listdir(faults)):
        if not file.endswith(".ts"):
            continue
        path = os.path.join(faults, file)
        box, extent = case_box(read_surface(path)[0])
        yield f"{case_name(path)}, E/{DIVISOR}", path, ",".join(repr(c) for c in box), extent / DIVISOR


def run(cli, surface, box, resolution, threads, work):
    report = os.path.join(work, "report.json")
    command = [cli, "--box", box, "--surface", surface, "--resolution", repr(resolution), "--threads", str(threads),
               "--quiet", "--output", os.path.join(work, "mesh.msh"), "--report", report]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        return None
    with open(report) as f:
        return json.load(f)


def summary(report):
    smoothing = report["smoothing"]
    quality = report["quality"]["after_smoothing"]
    updates = sum(sweep["nodes_optimised"] for sweep in smoothing["sweeps"])
    return {
        "seconds": report["seconds"]["smoothing"],
        "step4": report["seconds"]["smoothing"] + report["seconds"].get("improvement", 0.0),
        "total": report["seconds"]["total"],
        "sweeps": len(smoothing["sweeps"]),
        "updates": updates,
        "eta": (quality["meccano"]["min"], quality["meccano"]["mean"], quality["equilateral"]["min"],
                quality["equilateral"]["mean"]),
        "dihedral": (report["min_dihedral_deg"], report["max_dihedral_deg"]),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--faults", default=os.path.join(REPOSITORY, "..", "shared", "data", "faults"))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    args = parser.parse_args()

    print("| case | tets | SUS s before | after | speed-up | SUS + improvement s before / after | insertion s before / after "
          "| sweeps before / after | µs per node update before / after | η meccano min / mean before | after | η equilateral min / mean before | after | dihedral before | after "
          "| largest η difference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for name, surface, box, resolution in cases(args.faults):
            best = {"before": None, "after": None}
            tets = 0
            for _ in range(args.repeat):
                for label in ("before", "after"):
                    report = run(getattr(args, label), surface, box, resolution, args.threads, work)
                    if report is None:
                        continue
                    tets = report["tets"]
                    measured = summary(report)
                    if best[label] is None or measured["seconds"] < best[label]["seconds"]:
                        best[label] = measured
            b, a = best["before"], best["after"]
            if b is None or a is None:
                print(f"| {name} | | {'failed' if b is None else ''} | {'failed' if a is None else ''} |" + " |" * 12)
                continue
            per_update = [1e6 * m["seconds"] / max(m["updates"], 1) for m in (b, a)]
            difference = max(abs(x - y) for x, y in zip(b["eta"], a["eta"]))
            print(f"| {name} | {tets:,} | {b['seconds']:.2f} | {a['seconds']:.2f} | {b['seconds'] / a['seconds']:.2f}× "
                  f"| {b['step4']:.2f} / {a['step4']:.2f} | {b['total']:.2f} / {a['total']:.2f} "
                  f"| {b['sweeps']} / {a['sweeps']} | {per_update[0]:.1f} / {per_update[1]:.1f} "
                  f"| {b['eta'][0]:.3f} / {b['eta'][1]:.3f} | {a['eta'][0]:.3f} / {a['eta'][1]:.3f} "
                  f"| {b['eta'][2]:.3f} / {b['eta'][3]:.3f} | {a['eta'][2]:.3f} / {a['eta'][3]:.3f} "
                  f"| {b['dihedral'][0]:.1f}–{b['dihedral'][1]:.1f}° | {a['dihedral'][0]:.1f}–{a['dihedral'][1]:.1f}° "
                  f"| {difference:.4f} |", flush=True)


if __name__ == "__main__":
    main()
