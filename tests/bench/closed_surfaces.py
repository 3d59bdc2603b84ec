#!/usr/bin/python3
"""Closed surfaces (issue 19) through the CLI, against Gmsh HXT (doc/benchmarks.md, "Closed surfaces").

usage: closed_surfaces.py [--build DIR] [--work DIR] [--divisors 5,10,20] [--cases sphere,...] [--no-hxt]

Each case is a closed surface (or two) written as OBJ, generated here: a sphere, an ellipsoid turned
about an oblique axis, a thin ellipsoid (a disk-like inclusion 0.1 thick), bumpy blobs (smooth, and rough
with six bumps), a sphere with jittered vertices (irregular triangles), a coarse sphere (large flat facets
meeting at 20-30 degree creases), a rounded cube (superellipsoid: near-flat sides, tight edges), two
spheres 0.05 apart, a sphere 0.05 from the box, and an ellipsoid in a 2 x 1 x 1 box. R is the case's
largest radius; l_r = R / divisor. Each result is checked with `meccano-immerse check` (closed interface,
inside group) and measured against its OBJ with `meccano-immerse measure`.

HXT: `reference-gmsh` on the same box and surfaces, each triangulated anew at about the module's mean
interface edge h_S (the octahedral sphere's n chosen for it), with the graded size of the faults'
benchmark (--size-near-surface h_S --size-distance 4 l_r --size 0.3 x the box's shortest side): the
same interface resolution, in the same run. Gmsh 4.8.4's HXT leaves holes next to an inclusion on some
meshes, which reference-gmsh refuses: that mesh is made again with Gmsh's Delaunay (marked); each Gmsh
mesh is checked too.
Timings are single runs: compare rows, not runs.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "meshes"))
from generate_surfaces import octahedral_sphere  # noqa: E402


def rotation(axis, angle):
    x, y, z = (c / math.sqrt(sum(a * a for a in axis)) for c in axis)
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]


def ellipsoid(centre, radii, turn=None):
    m = rotation(*turn) if turn else [[1, 0, 0], [0, 1, 0], [0, 0, 1]]

    def place(d):
        e = [radii[i] * d[i] for i in range(3)]
        return tuple(centre[i] + sum(m[i][j] * e[j] for j in range(3)) for i in range(3))
    return place


def blob(centre, radius, amplitude, bumps):
    def place(d):
        b = sum(math.exp(-sum((d[i] - u[i]) ** 2 for i in range(3)) / 0.3) for u in bumps)
        r = radius * (1 + amplitude * b)
        return tuple(centre[i] + r * d[i] for i in range(3))
    return place


def rounded_cube(centre, half, power=6):
    def place(d):
        scale = sum(abs(c) ** power for c in d) ** (-1.0 / power)
        return tuple(centre[i] + half * scale * d[i] for i in range(3))
    return place


def unit_bumps(count, seed):
    rng = random.Random(seed)
    bumps = []
    for _ in range(count):
        v = [rng.gauss(0, 1) for _ in range(3)]
        r = math.sqrt(sum(c * c for c in v))
        bumps.append(tuple(c / r for c in v))
    return bumps


UNIT = (0, 0, 0, 1, 1, 1)
# name: (box, [(place, radius, jitter)], R). The octahedral n of each surface is chosen per run.
CASES = {
    "sphere": (UNIT, [(ellipsoid((0.5, 0.5, 0.5), (0.3, 0.3, 0.3)), 0)], 0.3),
    "ellipsoid_turned": (UNIT, [(ellipsoid((0.5, 0.5, 0.5), (0.38, 0.22, 0.15), ((1, 2, 3), 0.7)), 0)], 0.38),
    "thin_ellipsoid": (UNIT, [(ellipsoid((0.5, 0.5, 0.5), (0.35, 0.3, 0.05), ((1, 0, 1), 0.4)), 0)], 0.35),
    "blob": (UNIT, [(blob((0.5, 0.5, 0.5), 0.25, 0.25, unit_bumps(3, 1)), 0)], 0.35),
    "rough_blob": (UNIT, [(blob((0.5, 0.5, 0.5), 0.22, 0.45, unit_bumps(6, 2)), 0)], 0.4),
    "jittered_sphere": (UNIT, [(ellipsoid((0.5, 0.5, 0.5), (0.3, 0.3, 0.3)), 0.2)], 0.3),
    "coarse_sphere": (UNIT, [(ellipsoid((0.5, 0.5, 0.5), (0.3, 0.3, 0.3)), -3)], 0.3),
    "rounded_cube": (UNIT, [(rounded_cube((0.5, 0.5, 0.5), 0.28), 0)], 0.4),
    "two_spheres": (UNIT, [(ellipsoid((0.29, 0.5, 0.5), (0.2, 0.2, 0.2)), 0),
                           (ellipsoid((0.74, 0.5, 0.5), (0.2, 0.2, 0.2)), 0)], 0.2),
    "near_box": (UNIT, [(ellipsoid((0.65, 0.5, 0.5), (0.3, 0.3, 0.3)), 0)], 0.3),
    "long_box": ((0, 0, 0, 2, 1, 1), [(ellipsoid((1.0, 0.5, 0.5), (0.8, 0.3, 0.25)), 0)], 0.8),
}


def surface_file(work, case, k, place, n, jitter):
    """The OBJ of surface k of a case at octahedral resolution n. jitter > 0: directions jittered by
    jitter / n (irregular triangles on the same surface); jitter < 0: n = -jitter (a coarse polyhedron)."""
    path = os.path.join(work, "%s_%d_n%d.obj" % (case, k, n))
    if os.path.exists(path):
        return path
    if jitter > 0:
        rng = random.Random(7 + n)

        def shaken(d, place=place):
            v = [d[i] + rng.uniform(-1, 1) * jitter / n for i in range(3)]
            r = math.sqrt(sum(c * c for c in v))
            return place(tuple(c / r for c in v))
        points, triangles = octahedral_sphere(shaken, n)
    else:
        points, triangles = octahedral_sphere(place, n)
    with open(path, "w") as out:
        for p in points:
            out.write("v %.17g %.17g %.17g\n" % p)
        for t in triangles:
            out.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
    return path


def octahedral_n(radius, edge):
    """n whose octahedral sphere of this radius has mean edges of about `edge`."""
    return max(2, int(round(math.pi * radius / (2 * edge) * 1.15)))


def run(command, timeout=3600):
    start = time.time()
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    return done, time.time() - start


def add_insertion_figures(row, done, stem):
    """The figures of an insertion's report STEM.json in row, or its error if it failed (then False)."""
    if done.returncode != 0:
        row["error"] = (done.stderr.strip().splitlines() or ["?"])[-1][:300]
        return False
    report = json.load(open(stem + ".json"))
    after = report["quality"]["after_smoothing"]
    row.update(tets=report["tets"], seconds=report["seconds"]["total"], sus=report["seconds"]["smoothing"],
               eta_meccano=after["meccano"]["min"], eta_equilateral=after["equilateral"]["min"],
               dihedral=(after["min_dihedral_deg"], after["max_dihedral_deg"]))
    return True


def module_run(args, work, case, divisor):
    box, surfaces, radius = CASES[case]
    resolution = radius / divisor
    names = []
    for k, (place, jitter) in enumerate(surfaces):
        n = -jitter if jitter < 0 else octahedral_n(radius, resolution / 2)
        names.append(surface_file(work, case, k, place, n, jitter) + ":%s_%d" % (case, k))
    stem = os.path.join(work, "%s_d%d" % (case, divisor))
    command = [os.path.join(args.build, "module", "meccano-immerse"), "--box", ",".join(map(str, box)),
               "--level", "3", "--resolution", repr(resolution), "--output", stem + ".msh",
               "--report", stem + ".json"]
    for name in names:
        command += ["--surface", name]
    done, seconds = run(command)
    row = {"case": case, "divisor": divisor, "l_r": resolution, "status": done.returncode, "wall": seconds,
           "retries": done.stdout.count("retrying with") + done.stderr.count("retrying with")}
    if not add_insertion_figures(row, done, stem):
        return row
    check, _ = run([os.path.join(args.build, "module", "meccano-immerse"), "check", stem + ".msh", "--quiet"])
    row["check"] = check.returncode == 0
    measure = [os.path.join(args.build, "module", "meccano-immerse"), "measure", stem + ".msh", "--quiet",
               "--report", stem + "_measure.json"]
    for name in names:
        measure += ["--surface", name]
    run(measure)
    interfaces = json.load(open(stem + "_measure.json"))["interfaces"]
    row["normal_max"] = max(i["normal_deviation_deg"]["max"] for i in interfaces)
    row["normal_mean"] = max(i["normal_deviation_deg"]["mean"] for i in interfaces)
    row["hausdorff"] = max(i["hausdorff"] for i in interfaces)
    row["node_distance"] = max(i["node_distance"]["max"] for i in interfaces)
    area = sum(i["area"] for i in interfaces)
    faces = sum(i["faces"] for i in interfaces)
    row["h_S"] = math.sqrt(4 * area / faces / math.sqrt(3))  # the equilateral triangle of the mean area
    return row


def hxt_run(args, work, case, row):
    box, surfaces, radius = CASES[case]
    names = []
    for k, (place, jitter) in enumerate(surfaces):
        n = octahedral_n(radius, row["h_S"])
        names.append(surface_file(work, case, k, place, n, max(jitter, 0)) + ":%s_%d" % (case, k))
    stem = os.path.join(work, "%s_d%d_gmsh" % (case, row["divisor"]))
    size = 0.3 * min(box[3] - box[0], box[4] - box[1], box[5] - box[2])
    # Gmsh 4.8.4's HXT leaves holes between the box and an inclusion's volume on some meshes, which
    # reference-gmsh refuses; such a run is redone with Gmsh's Delaunay and marked so.
    for algorithm in ("hxt", "delaunay"):
        command = [os.path.join(args.build, "reference", "reference-gmsh"), "--box"] + [str(c) for c in box] + [
            "--size", repr(size), "--size-near-surface", repr(min(row["h_S"], size)),
            "--size-distance", repr(4 * row["l_r"]), "--threads", "2", "--quiet", "--algorithm", algorithm,
            "--output", stem + ".msh", "--report", stem + ".json"]
        for name in names:
            command += ["--surface", name]
        done, _ = run(command)
        if done.returncode != 0:
            if algorithm == "hxt" and "holes" in done.stderr:
                continue
            return {"status": done.returncode, "error": (done.stderr.strip().splitlines() or ["?"])[-1][:200]}
        check, _ = run([os.path.join(args.build, "module", "meccano-immerse"), "check", stem + ".msh", "--quiet"])
        break
    report = json.load(open(stem + ".json"))
    return {"status": 0, "tets": report["tets"], "seconds": report["seconds"]["total"], "algorithm": algorithm,
            "valid": check.returncode == 0, "quality": report["quality"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(HERE, "..", "..", "build"))
    parser.add_argument("--work", default="/tmp/closed_surfaces")
    parser.add_argument("--divisors", default="5,10,20")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--no-hxt", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    print("| case | l_r | exit | tets | seconds (SUS) | retries | check | η min meccano / equilateral | dihedral "
          "| normal dev. max / mean | Hausdorff | node dist. | HXT tets | HXT s | HXT η min | HXT dihedral |")
    print("|" + "---|" * 16)
    for case in args.cases.split(","):
        for divisor in map(int, args.divisors.split(",")):
            row = module_run(args, args.work, case, divisor)
            if row["status"] != 0:
                print("| %s | R/%d | %d | – | %.1f | %d | – | %s |" % (case, divisor, row["status"], row["wall"],
                                                                    row["retries"], row["error"]), flush=True)
                continue
            hxt = {"status": -1} if args.no_hxt else hxt_run(args, args.work, case, row)
            if hxt["status"] == 0:
                q = hxt["quality"]
                hxt_cells = "%d%s | %.2f | %.3f | %.1f–%.1f°" % (
                    hxt["tets"], "" if hxt["algorithm"] == "hxt" else " (Delaunay%s)" % (
                        "" if hxt["valid"] else ", invalid"), hxt["seconds"], q["equilateral"]["min"],
                    q["min_dihedral_deg"], q["max_dihedral_deg"])
            else:
                hxt_cells = "– | – | – | %s" % hxt.get("error", "not run")
            print("| %s | R/%d | 0 | %d | %.2f (%.2f) | %d | %s | %.3f / %.3f | %.1f–%.1f° | %.1f / %.2f° | %.2g | %.1g "
                  "| %s |" % (case, divisor, row["tets"], row["seconds"], row["sus"], row["retries"],
                              "ok" if row["check"] else "FAILED", row["eta_meccano"], row["eta_equilateral"],
                              row["dihedral"][0], row["dihedral"][1], row["normal_max"], row["normal_mean"],
                              row["hausdorff"], row["node_distance"], hxt_cells), flush=True)


if __name__ == "__main__":
    main()
