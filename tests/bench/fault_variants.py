#!/usr/bin/env python3
"""Variants of the shared faults, inserted through the CLI (doc/robustness.md, "Fault variants").

usage: fault_variants.py [--build DIR] [--work DIR] [--divisors 30,50] [--variants rot37,tilt25,...]
                         [--margins 0.1,...]

The project is judged on faults it has not seen, so each shared fault (../shared/data/faults) is also
inserted as something it is not: turned 37 degrees about the vertical (rot37), tilted 25 degrees about
the east axis (tilt25), with its normals flipped (flip), in kilometres instead of metres (km), and cut
to a part of itself along its triangles (cropA: the 60 % of its length at one end of its strike, cropB:
the 45 % at the other; the largest edge-connected part, skipped unless a disk). A cut leaves a jagged
(sawtooth) rim with notches and 50-60 degree tips, which the shared faults do not have. The variant asis
is the fault as it is, for other boxes and resolutions (not run by default). Each variant is written as
OBJ and inserted at l_r = E / divisor in its bounding box grown by margin x E per side (E its largest
extent; 0.1, bench_faults' box, by default); each result is checked with `meccano-immerse check`. Prints
one line per run: exit status, seconds, tets, retries (finer l_r, other side), the untangling flips made
(flips:N) and why.
"""
import argparse
import glob
import itertools
import json
import math
import os
import subprocess
import time
from collections import defaultdict

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
FAULTS = os.path.join(HERE, "..", "..", "..", "shared", "data", "faults")


def read_ts(path):
    ids, points, triangles = {}, [], []
    for line in open(path, errors="replace"):
        w = line.split()
        if not w:
            continue
        if w[0] in ("VRTX", "PVRTX"):
            ids[int(w[1])] = len(points)
            points.append([float(w[2]), float(w[3]), float(w[4])])
        elif w[0] in ("ATOM", "PATOM"):
            ids[int(w[1])] = ids[int(w[2])]
        elif w[0] == "TRGL":
            triangles.append([ids[int(w[1])], ids[int(w[2])], ids[int(w[3])]])
    return weld(np.array(points), np.array(triangles), 1.0)


def weld(points, triangles, tolerance):
    """Merges points on one grid cell of `tolerance` (the CLI welds within 1 m too) and drops collapsed triangles."""
    key, remap, welded = {}, np.zeros(len(points), int), []
    for i, x in enumerate(points):
        k = tuple(np.round(x / tolerance).astype(np.int64))
        if k not in key:
            key[k] = len(welded)
            welded.append(x)
        remap[i] = key[k]
    t = remap[triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    return np.array(welded), t


def edges_of(triangles):
    edges = defaultdict(list)
    for i, t in enumerate(triangles):
        for a, b in ((0, 1), (1, 2), (2, 0)):
            edges[tuple(sorted((t[a], t[b])))].append(i)
    return edges


def largest_part(triangles):
    edges = edges_of(triangles)
    part = -np.ones(len(triangles), int)
    sizes = []
    for seed in range(len(triangles)):
        if part[seed] >= 0:
            continue
        part[seed], stack, size = len(sizes), [seed], 0
        while stack:
            i = stack.pop()
            size += 1
            t = triangles[i]
            for a, b in ((0, 1), (1, 2), (2, 0)):
                for j in edges[tuple(sorted((t[a], t[b])))]:
                    if part[j] < 0:
                        part[j] = len(sizes)
                        stack.append(j)
        sizes.append(size)
    return triangles[part == int(np.argmax(sizes))]


def is_disk(triangles):
    edges = edges_of(triangles)
    if max(len(v) for v in edges.values()) > 2:
        return False
    degree = defaultdict(int)
    for (a, b), on in edges.items():
        if len(on) == 1:
            degree[a] += 1
            degree[b] += 1
    euler = len(set(triangles.ravel())) - len(edges) + len(triangles)
    return euler == 1 and all(d == 2 for d in degree.values())


def rotation(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    if axis == "z":
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def variants(points, triangles):
    centre = points.mean(axis=0)
    yield "asis", points, triangles
    yield "rot37", (points - centre) @ rotation("z", 37).T + centre, triangles
    yield "tilt25", (points - centre) @ rotation("x", 25).T + centre, triangles
    yield "flip", points, triangles[:, ::-1]
    yield "km", points / 1000.0, triangles
    strike = np.linalg.svd(points - centre, full_matrices=False)[2][0]
    along = (points[triangles].mean(axis=1) - centre) @ strike
    for name, keep in (("cropA", along < np.quantile(along, 0.6)), ("cropB", along > np.quantile(along, 0.55))):
        part = largest_part(triangles[keep])
        if is_disk(part):
            yield name, points, part


def write_obj(path, points, triangles):
    used = np.unique(triangles.ravel())
    index = -np.ones(len(points), int)
    index[used] = np.arange(len(used))
    with open(path, "w") as f:
        f.writelines(f"v {x[0]:.6f} {x[1]:.6f} {x[2]:.6f}\n" for x in points[used])
        f.writelines(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in index[triangles])
    return points[used]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(HERE, "..", "..", "build"))
    parser.add_argument("--work", default="/tmp/meccano-fault-variants")
    parser.add_argument("--divisors", default="30,50")
    parser.add_argument("--variants", default="rot37,tilt25,flip,km,cropA,cropB")
    parser.add_argument("--margins", default="0.1", help="box margins, as fractions of E")
    args = parser.parse_args()
    tool = os.path.join(args.build, "module", "meccano-immerse")
    os.makedirs(args.work, exist_ok=True)
    wanted = args.variants.split(",")
    for ts in sorted(glob.glob(os.path.join(FAULTS, "*.ts"))):
        fault = os.path.basename(ts).split("-")[3]
        for variant, points, triangles in variants(*read_ts(ts)):
            if variant not in wanted:
                continue
            obj = os.path.join(args.work, f"{fault}_{variant}.obj")
            used = write_obj(obj, points, triangles)
            low, high = used.min(axis=0), used.max(axis=0)
            extent = (high - low).max()
            for margin, divisor in itertools.product(map(float, args.margins.split(",")),
                                                     map(int, args.divisors.split(","))):
                box = ",".join(f"{v:.6f}" for v in list(low - margin * extent) + list(high + margin * extent))
                msh = os.path.join(args.work, f"{fault}_{variant}_{margin:g}_{divisor}.msh")
                command = [tool, "--box", box, "--surface", obj + ":fault", "--resolution", f"{extent / divisor:.6g}",
                           "--output", msh, "--report", msh + ".json", "--quiet"]
                start = time.time()
                run = subprocess.run(command, capture_output=True, text=True)
                seconds = time.time() - start
                label = f"{fault:36s} {variant:6s} {margin:<4g} E/{divisor:<3d}"
                if run.returncode != 0:
                    why = (run.stderr.strip().splitlines() or ["?"])[-1][:300]
                    print(f"{label} FAIL {seconds:7.1f} s  {why}", flush=True)
                    continue
                check = subprocess.run([tool, "check", msh, "--quiet"], capture_output=True, text=True)
                report = json.load(open(msh + ".json"))
                finer = report["surfaces"][0]["resolution"] < 0.999 * extent / divisor
                status = "ok" if check.returncode == 0 else "INVALID"
                flips = report["smoothing"].get("untangling_flips", {}).get("operations", {})
                retries = (("finer " if finer else "") + ("side " if report.get("side_retry") else "") +
                           (f"flips:{sum(flips.values())} " if sum(flips.values()) else ""))
                print(f"{label} {status:4s} {seconds:7.1f} s {report['tets']:>9d} tets "
                      f"{retries or '-'} {report.get('side_retry') or ''}"[:400], flush=True)
                os.remove(msh)


if __name__ == "__main__":
    main()
