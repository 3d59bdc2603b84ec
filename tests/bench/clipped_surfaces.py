#!/usr/bin/python3
"""Surfaces clipped by the box (issue 19, deliverable 1) through the CLI (doc/benchmarks.md, "Surfaces
that reach the box").

usage: clipped_surfaces.py [--build DIR] [--work DIR] [--divisors 30,50] [--cases NAME,...] [--faults DIR]
                           [--snap FRACTION]

Synthetic cases, in the unit box unless said: planes across the box along z and x, an oblique plane
through four faces, a plane cutting off a box corner (three faces, three box edges), a wavy sheet across a
2 x 1 x 1 box, and near-vertical faults leaving through the top only, the top and one side (through a box
edge), and three faces. Real cases: every fault of ../shared/data/faults/ in its box of bench_faults.py
(its bounding box grown by E/10), with the box top lowered to elevation 0 (the ground, where the faults
reach up to +1.6 km) and to the faults' mean top (the mean elevation of the rim vertices in the top tenth
of the fault's height), each also with `--snap-to-box E * FRACTION` (cases `_z0_snap`, `_mean_top_snap`;
default FRACTION 1/200, about 300 m: the rim set onto the box where it runs that close to it). E is the case's
largest extent (the box's for synthetic cases, the fault's for real
ones); l_r = E / divisor. Each result is checked with `meccano-immerse check` and measured against the
surface with `meccano-immerse measure` (which clips it to the mesh's box as the insertion does).
Timings are single runs: compare rows, not runs.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from bench_faults import bounding_box, case_box, read_surface  # noqa: E402
from closed_surfaces import add_insertion_figures  # noqa: E402

UNIT = [0, 0, 0, 1, 1, 1]


def graph(f, x_range, y_range, n, turn=False):
    """z = f(x, y) over the ranges, n x n cells; with turn, (x, y, z) -> (z, x, y) (a rotation)."""
    points, triangles = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x = x_range[0] + (x_range[1] - x_range[0]) * i / n
            y = y_range[0] + (y_range[1] - y_range[0]) * j / n
            points.append((f(x, y), x, y) if turn else (x, y, f(x, y)))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            triangles += [(a, b, d), (a, d, c)] if (i + j) % 2 else [(a, b, c), (b, d, c)]
    return points, triangles


def fault(y_range, z_range):
    return graph(lambda y, z: 0.45 + 0.1 * z + 0.03 * math.sin(5 * y), y_range, z_range, 40, turn=True)


# name: (box, surface); the surfaces reach beyond the box.
SYNTHETIC = {
    "plane_z": (UNIT, graph(lambda x, y: 0.5, (-0.3, 1.3), (-0.3, 1.3), 24)),
    "plane_x": (UNIT, graph(lambda x, y: 0.5, (-0.3, 1.3), (-0.3, 1.3), 24, turn=True)),
    "plane_oblique": (UNIT, graph(lambda x, y: 0.3 + 0.35 * x + 0.1 * y, (-0.3, 1.3), (-0.3, 1.3), 24)),
    "corner_cut": (UNIT, graph(lambda x, y: 0.6 - x - y, (-0.3, 0.9), (-0.3, 0.9), 24)),
    "wavy_long_box": ([0, 0, 0, 2, 1, 1],
                      graph(lambda x, y: 0.5 + 0.1 * math.sin(3 * x) * math.cos(2 * y), (-0.3, 2.3), (-0.3, 1.3), 48)),
    "fault_top": (UNIT, fault((0.2, 0.8), (0.3, 1.2))),
    "fault_top_side": (UNIT, fault((0.3, 1.2), (0.3, 1.2))),
    "fault_three_faces": (UNIT, fault((-0.2, 1.2), (0.3, 1.2))),
}


def write_obj(path, points, triangles):
    with open(path, "w") as out:
        for p in points:
            out.write("v %.17g %.17g %.17g\n" % tuple(p))
        for t in triangles:
            out.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def mean_top(points, triangles):
    """The mean elevation of the fault's rim vertices in the top tenth of its height."""
    uses = {}
    for t in triangles:
        for k in range(3):
            edge = tuple(sorted((t[k], t[(k + 1) % 3])))
            uses[edge] = uses.get(edge, 0) + 1
    rim = {v for edge, n in uses.items() if n == 1 for v in edge}
    low, high = bounding_box(points)
    top = [points[v][2] for v in rim if points[v][2] >= high[2] - 0.1 * (high[2] - low[2])]
    return sum(top) / len(top)


def cases(args):
    """name -> (box, surface file, E, --snap-to-box distance or 0)."""
    found = {}
    for name, (box, (points, triangles)) in SYNTHETIC.items():
        path = os.path.join(args.work, name + ".obj")
        write_obj(path, points, triangles)
        found[name] = (box, path, max(box[3] - box[0], box[4] - box[1], box[5] - box[2]), 0.0)
    if os.path.isdir(args.faults):
        for file in sorted(os.listdir(args.faults)):
            if not file.endswith(".ts"):
                continue
            path = os.path.join(args.faults, file)
            points, triangles = read_surface(path)
            box, extent = case_box(points)
            short = file.split("-")[3].split("_fault")[0] if file.count("-") >= 3 else file
            for top_name, top in (("_z0", 0.0), ("_mean_top", mean_top(points, triangles))):
                found[short + top_name] = (box[:5] + [top], path, extent, 0.0)
                found[short + top_name + "_snap"] = (box[:5] + [top], path, extent, args.snap * extent)
    return found


TIMEOUT = 600  # seconds; a run beyond it is reported as such


def run(command):
    start = time.time()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        done = subprocess.CompletedProcess(command, -1, "", "stopped after %d s" % TIMEOUT)
    return done, time.time() - start


def module_run(args, name, box, path, extent, snap, divisor):
    tool = os.path.join(args.build, "module", "meccano-immerse")
    stem = os.path.join(args.work, "%s_d%d" % (name, divisor))
    resolution = extent / divisor
    done, wall = run([tool, "--box", ",".join(repr(c) for c in box), "--surface", path + ":S", "--resolution",
                      repr(resolution), "--snap-to-box", repr(snap), "--output", stem + ".msh", "--report",
                      stem + ".json"])
    row = {"status": done.returncode, "wall": wall, "retries": done.stdout.count("retrying")}
    if not add_insertion_figures(row, done, stem):
        return row
    check, _ = run([tool, "check", stem + ".msh", "--quiet"])
    row["check"] = check.returncode == 0
    run([tool, "measure", stem + ".msh", "--surface", path + ":S", "--quiet", "--report", stem + "_measure.json"])
    interfaces = [i for i in json.load(open(stem + "_measure.json"))["interfaces"] if "hausdorff" in i]
    row["normal"] = (max(i["normal_deviation_deg"]["max"] for i in interfaces),
                     max(i["normal_deviation_deg"]["mean"] for i in interfaces))
    row["hausdorff"] = max(i["hausdorff"] for i in interfaces) / extent
    row["area_ratio"] = min(i["area_ratio"] for i in interfaces)
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(HERE, "..", "..", "build"))
    parser.add_argument("--work", default="/tmp/clipped_surfaces")
    parser.add_argument("--faults", default=os.path.join(HERE, "..", "..", "..", "shared", "data", "faults"))
    parser.add_argument("--divisors", default="30,50")
    parser.add_argument("--cases", default="")
    parser.add_argument("--snap", type=float, default=1 / 200)
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    print("| case | l_r | exit | tets | seconds (SUS) | retries | check | η min meccano / equilateral | dihedral "
          "| normal dev. max / mean | Hausdorff / E | area ratio |")
    print("|" + "---|" * 12)
    for name, (box, path, extent, snap) in cases(args).items():
        if args.cases and name not in args.cases.split(","):
            continue
        for divisor in map(int, args.divisors.split(",")):
            row = module_run(args, name, box, path, extent, snap, divisor)
            if row["status"] != 0:
                print("| %s | E/%d | %d | – | %.1f | %d | – | %s |" % (name, divisor, row["status"], row["wall"],
                                                                    row["retries"], row["error"]), flush=True)
                continue
            print("| %s | E/%d | 0 | %d | %.2f (%.2f) | %d | %s | %.3f / %.3f | %.1f–%.1f° | %.1f / %.2f° | %.1e | %.4f |"
                  % (name, divisor, row["tets"], row["seconds"], row["sus"], row["retries"],
                     "ok" if row["check"] else "FAILED", row["eta_meccano"], row["eta_equilateral"], row["dihedral"][0],
                     row["dihedral"][1], row["normal"][0], row["normal"][1], row["hausdorff"], row["area_ratio"]),
                  flush=True)


if __name__ == "__main__":
    main()
