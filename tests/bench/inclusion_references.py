#!/usr/bin/python3
"""The demo solver's inclusion problem on the module's meshes and on Gmsh's (doc/comparison.md, "The
inclusion problem"): the same coefficient jump across a sphere solved on every mesh, errors at equal DoFs.

usage: inclusion_references.py [--build DIR] [--work DIR] [--levels 9,12,15] [--sizes 0.1,0.07,0.05,0.035,0.025,0.018]

meccano-immerse in two families, as doc/comparison.md c: "edge / 4" is `convergence_study --problem
inclusion` (the unit cube's meccano at base level K, l_r a quarter of its longest edge: the tets at S
refined twice), "edge" has l_r just above that edge (S inserted into the base mesh as it is); the sphere
triangulated with n = ceil(pi R / (edge / 4)) cells per octant edge in both. Gmsh: `reference-gmsh --algorithm delaunay` (Gmsh 4.8.4's HXT leaves holes beside an
inclusion) at uniform size H, the sphere triangulated at about H (its triangles are kept). Every mesh
is checked (`meccano-immerse check`), then `poisson_interface` solves the inclusion problem on it with P1
and with P2 (cells curved onto the sphere). Prints a Markdown table per mesh, and at each module run's
DoFs Gmsh's error there (log-log interpolation between its runs) and the module's ratio to it.
Single runs, one after the other: read seconds loosely.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "meshes"))
from generate_surfaces import inclusion_sphere, write_obj  # noqa: E402

sys.path.insert(0, HERE)
from compare_references import loglog_interpolate, markdown_table, thousands  # noqa: E402

RADIUS = 0.3
BOX = "0,0,0,1,1,1"


def run(command, log):
    with open(log, "w") as out:
        if subprocess.run(command, stdout=out, stderr=subprocess.STDOUT).returncode != 0:
            sys.exit(f"inclusion_references: failed: {' '.join(command)} (see {log})")


def sphere_file(work, n):
    path = os.path.join(work, f"sphere_{n}.obj")
    if not os.path.exists(path):
        write_obj(path, *inclusion_sphere(n), f"inclusion sphere, n = {n}")
    return path


def solve(build, work, mesh, label):
    """P1 and P2 errors on one mesh, as {degree: report}; the inclusion problem must be recognised."""
    reports = {}
    for degree in (1, 2):
        report = os.path.join(work, f"{label}.p{degree}.json")
        run([os.path.join(build, "solver_demo", "poisson_interface"), "--mesh", mesh, "--degree", str(degree),
             "--report", report], os.path.join(work, f"{label}.p{degree}.log"))
        with open(report) as f:
            reports[degree] = json.load(f)
        if reports[degree]["problem"] != "inclusion":
            sys.exit(f"inclusion_references: {mesh} was not taken for the inclusion (see {label}.p{degree}.log)")
    return reports


def mesh_case(build, work, tool, parameter):
    """Meshes one case, checks it, solves on it; returns its row of numbers."""
    cli = os.path.join(build, "module", "meccano-immerse")
    label = re.sub(r"[^a-z0-9.]+", "_", f"{tool} {parameter}".lower())  # a file name
    mesh, report = os.path.join(work, f"{label}.msh"), os.path.join(work, f"{label}.json")
    start = time.time()
    if tool.startswith("meccano-immerse"):
        level = int(parameter)
        edge = math.sqrt(3.0) * 2.0 ** (-level / 3.0)  # the base mesh's longest edge
        resolution = 0.25 * edge if tool.endswith("edge / 4") else 1.01 * edge
        n = math.ceil(math.pi * RADIUS / (0.25 * edge))
        run([cli, "--box", BOX, "--level", str(level), "--surface", sphere_file(work, n) + ":sphere",
             "--resolution", repr(resolution), "--output", mesh, "--report", report, "--quiet"],
            os.path.join(work, f"{label}.log"))
        text = f"K {level}, l_r {resolution:.4f}, n {n}"
    else:
        size = float(parameter)
        n = max(4, round(math.pi * RADIUS / (2.0 * size)))
        run([os.path.join(build, "reference", "reference-gmsh"), "--box", BOX, "--surface",
             sphere_file(work, n) + ":sphere", "--size", repr(size), "--algorithm", "delaunay", "--output", mesh,
             "--report", report, "--quiet"], os.path.join(work, f"{label}.log"))
        text = f"H {size}, n {n}"
    seconds = time.time() - start
    run([cli, "check", mesh, "--quiet"], os.path.join(work, f"{label}.check.log"))
    with open(report) as f:
        quality = json.load(f)
    solved = solve(build, work, mesh, label)
    os.remove(mesh)
    # The module's final quality is under after_smoothing, reference-gmsh's at the top of `quality`.
    summary = quality["quality"].get("after_smoothing", quality["quality"])
    return {"tool": tool, "parameter": text, "tets": solved[1]["cells"], "seconds": seconds,
            "eta_min": summary["equilateral"]["min"], "dihedral": (summary["min_dihedral_deg"], summary["max_dihedral_deg"]),
            "p1": solved[1], "p2": solved[2]}


def errors(row, degree):
    return row[f"p{degree}"]["dofs"], row[f"p{degree}"]["errors"]["l2"], row[f"p{degree}"]["errors"]["h1"]


def tables(rows):
    header = ["mesh", "parameter", "tets", "η min", "dihedral", "mesh s", "P1 DoFs", "P1 L2", "P1 H1",
              "P2 DoFs", "P2 L2", "P2 H1"]
    body = []
    for r in rows:
        line = [r["tool"], r["parameter"], thousands(r["tets"]), f"{r['eta_min']:.3f}",
                f"{r['dihedral'][0]:.1f}–{r['dihedral'][1]:.1f}°", f"{r['seconds']:.1f}"]
        for degree in (1, 2):
            dofs, l2, h1 = errors(r, degree)
            line += [thousands(dofs), f"{l2:.3e}", f"{h1:.3e}"]
        body.append(line)
    out = [markdown_table(header, body), "", "At each module run's DoFs, Gmsh's error there (log-log between its "
           "runs; * extrapolated) and the module's ratio to it:", ""]
    gmsh = [r for r in rows if not r["tool"].startswith("meccano-immerse")]
    body = []
    for r in rows:
        if r in gmsh:
            continue
        for degree in (1, 2):
            dofs, l2, h1 = errors(r, degree)
            line = [r["tool"], r["parameter"], f"P{degree}", thousands(dofs)]
            for index, value in ((1, l2), (2, h1)):
                reference, extrapolated = loglog_interpolate([errors(g, degree)[:1] + errors(g, degree)[index:index + 1]
                                                              for g in gmsh], dofs)
                line += [f"{value:.3e}", f"{reference:.3e}{'*' if extrapolated else ''}", f"{value / reference:.2f}"]
            body.append(line)
    return out + [markdown_table(["module", "parameter", "degree", "DoFs", "L2", "Gmsh L2", "ratio", "H1", "Gmsh H1", "ratio"], body)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--build", default=os.path.join(HERE, "..", "..", "build"))
    parser.add_argument("--work", default="/tmp/inclusion_references")
    parser.add_argument("--levels", default="9,12,15")
    parser.add_argument("--sizes", default="0.1,0.07,0.05,0.035,0.025,0.018")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rows = []
    cases = [(f"meccano-immerse, l_r = {family}", k) for family in ("edge / 4", "edge") for k in args.levels.split(",")]
    cases += [("Gmsh Delaunay", h) for h in args.sizes.split(",")]
    for tool, parameter in cases:
        rows.append(mesh_case(args.build, args.work, tool, parameter))
        print(f"{tool} {parameter}: {rows[-1]['tets']} tets", file=sys.stderr, flush=True)
    print("\n".join(tables(rows)))


if __name__ == "__main__":
    main()
