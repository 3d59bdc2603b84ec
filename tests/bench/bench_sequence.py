#!/usr/bin/env python3
"""A moving interface, step by step (issue 20; doc/comparison.md, "A moving surface, step by step").

usage: bench_sequence.py [--quick] [--build DIR] [--work DIR] [--hxt-every K] [--fault FILE.ts] [--cases A,B]

Cases (each 21 positions, step 0 as given; --quick: 6):
  patch_tilt       the 6 steps of comparison.md d (compare_references.py moved_patch): the cube example's
                   surface tilted by 1 degree and raised by 0.02 (1.3 l_r) per step, unit cube, level 12,
                   l_r = 1/64; always 6 positions, a motion beyond the issue's l_r / 2;
  patch_translate  the cube example's surface (compare_references.py moved 0 48) raised by l_r / 4 per
                   step, in the unit cube at level 12, l_r = 1/64 (the setting of comparison.md d);
  fault_translate  East Huasna (shared/data/faults) moved by l_r / 4 per step along its mean normal,
                   l_r = E / 50, E the largest extent of its bounding box;
  fault_rotate     the same fault turned by 1 degree per step about the vertical axis through its
                   centroid (its far ends move by about 0.4 l_r per step);
  fault_slide      a surface clipped by the box: the same fault with the box top halfway up its depth range,
                   moved by l_r / 4 per step along the horizontal part of its mean normal (so its
                   clipped triangulation stays the same); no HXT runs (reference-gmsh takes surfaces
                   inside the box only);
  sphere_grow      a closed surface: the inclusion's sphere (centre 0.5, radius 0.3, 4 608 triangles)
                   growing by l_r / 4 per step, unit cube, level 12, l_r = 1/64.
--fault FILE.ts moves another fault instead of East Huasna; --cases runs only the cases named.
The faults' box holds every position: the bounding box of all of them grown by E / 10 on every side.

Each case runs `meccano-immerse sequence` twice, one after the other: as it is (moving the interface
while it can) and with --from-scratch (every step inserted anew into the meccano mesh), both with SUS
in a band (sequence's default) and 2 threads. Every --hxt-every K-th step (default 10) and the last one are also meshed
by Gmsh HXT from scratch at equal interface resolution (reference-gmsh with the size field of
bench_faults.sh: the surface split to about the module's interface edge h_S, size h_S near it growing
to the far size at 4 l_r). Prints one Markdown table per case and a summary; seconds are single runs on
a machine that may be shared: compare the columns of one row.
"""
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "meshes"))
from bench_faults import bounding_box, far_size, read_surface  # noqa: E402
from generate_surfaces import octahedral_sphere  # noqa: E402
from compare_references import interface_edge, moved_patch  # noqa: E402

# Their surfaces reach beyond the box, which reference-gmsh refuses: no HXT column.
CLIPPED_CASES = {"fault_slide"}

DEFAULT_FAULT = os.path.join(HERE, "..", "..", "..", "shared", "data", "faults",
                     "CRFA-REHZ-EHSN-East_Huasna_fault-CFM4_1000m.ts")


def write_obj(path, points, triangles):
    with open(path, "w") as f:
        for p in points:
            f.write("v {!r} {!r} {!r}\n".format(*p))
        for t in triangles:
            f.write("f {} {} {}\n".format(*(v + 1 for v in t)))


def mean_normal(points, triangles):
    total = [0.0, 0.0, 0.0]
    for a, b, c in triangles:
        u = [points[b][k] - points[a][k] for k in range(3)]
        v = [points[c][k] - points[a][k] for k in range(3)]
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        total = [total[k] + n[k] for k in range(3)]
    length = math.sqrt(sum(x * x for x in total))
    return [x / length for x in total]


def patch_steps(count, motion):
    resolution = 1 / 64
    if motion == "tilt":
        positions = [moved_patch(k, 48)[0] for k in range(count)]
    else:
        points = moved_patch(0, 48)[0]
        positions = [[(x, y, z + k * resolution / 4) for x, y, z in points] for k in range(count)]
    return positions, moved_patch(0, 48)[1], "0,0,0,1,1,1", resolution, ["--level", "12"]


def sphere_steps(count):
    resolution = 1 / 64
    positions = []
    for k in range(count):
        radius = 0.3 + k * resolution / 4
        points, triangles = octahedral_sphere(lambda d: tuple(0.5 + radius * c for c in d), 24)
        positions.append(points)
    return positions, triangles, "0,0,0,1,1,1", resolution, ["--level", "12"]


def fault_steps(fault, count, motion):
    points, triangles = read_surface(fault)
    low, high = bounding_box(points)
    extent = max(high[k] - low[k] for k in range(3))
    resolution = extent / 50
    if motion in ("translate", "slide"):
        normal = mean_normal(points, triangles)
        if motion == "slide":  # along the ground: the horizontal part of the normal
            length = math.hypot(normal[0], normal[1])
            normal = [normal[0] / length, normal[1] / length, 0.0]
        positions = [[tuple(p[j] + k * resolution / 4 * normal[j] for j in range(3)) for p in points]
                     for k in range(count)]
    else:
        centre = [sum(p[j] for p in points) / len(points) for j in range(3)]
        positions = []
        for k in range(count):
            c, s = math.cos(math.radians(k)), math.sin(math.radians(k))
            positions.append([(centre[0] + c * (x - centre[0]) - s * (y - centre[1]),
                               centre[1] + s * (x - centre[0]) + c * (y - centre[1]), z) for x, y, z in points])
    low, high = bounding_box([p for position in positions for p in position])
    box = [low[k] - extent / 10 for k in range(3)] + [high[k] + extent / 10 for k in range(3)]
    if motion == "slide":
        box[5] = (low[2] + high[2]) / 2  # the box top cuts the fault across: it is clipped there at every step
    return positions, triangles, ",".join(repr(v) for v in box), resolution, []


def run_sequence(cli, files, box, resolution, extra, work, name, scratch):
    report = os.path.join(work, f"{name}.json")
    command = [cli, "sequence", "--box", box, "--resolution", repr(resolution), "--threads", "2", "--quiet",
               "--output", os.path.join(work, f"{name}_{{step}}.msh"), "--report", report] + extra
    for f in files:
        command += ["--step", f + ":surface"]
    if scratch:
        command.append("--from-scratch")
    subprocess.run(command, check=True)
    with open(report) as f:
        return json.load(f)["steps"]


def run_hxt(build, cli, surface, box, resolution, mesh, work, name):
    """Gmsh HXT from scratch at the interface resolution of the module's mesh `mesh`."""
    measure = os.path.join(work, f"{name}.measure.json")
    subprocess.run([cli, "measure", mesh, "--surface", surface + ":surface", "--quiet", "--report", measure],
                   check=True)
    with open(measure) as f:
        h_s = interface_edge(json.load(f))
    split = subprocess.run([sys.executable, os.path.join(HERE, "bench_faults.py"), "subdivide", surface,
                            repr(math.sqrt(2) * h_s), work], check=True, capture_output=True, text=True)
    split_surface = split.stdout.split()[0]
    numbers = [float(v) for v in box.split(",")]
    report = os.path.join(work, f"{name}.hxt.json")
    run = subprocess.run([os.path.join(build, "reference", "reference-gmsh"), "--box", box, "--algorithm", "hxt",
                          "--threads", "2", "--surface", split_surface + ":surface", "--size", repr(far_size(numbers)),
                          "--size-near-surface", repr(h_s), "--size-distance", repr(4 * resolution), "--quiet",
                          "--output", os.path.join(work, f"{name}.hxt.msh"), "--report", report],
                         capture_output=True, text=True)
    if run.returncode != 0:  # recorded in the table, the other runs go on
        return {"failed": (run.stderr.strip().splitlines() or [f"exit status {run.returncode}"])[-1]}
    with open(report) as f:
        return json.load(f)


def percent(part, whole):
    return f"{100 * part / whole:.1f} %"


def case_table(name, moving, scratch, hxt):
    print(f"\n### {name}\n")
    print("| step | mode | seconds moving / anew | speed-up | tets moving / anew | nodes unchanged moving / anew "
          "| η meccano min moving / anew | η equilateral min moving / anew | min dihedral moving / anew "
          "| HXT s (tets) | HXT s ÷ moving s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for m, s in zip(moving, scratch):
        h = hxt.get(m["step"])
        if h is None:
            hxt_cells = ("", "")
        elif "failed" in h:
            hxt_cells = (f"failed: {h['failed']}", "")
        else:
            hxt_cells = (f"{h['seconds']['total']:.2f} ({h['tets']:,})", f"{h['seconds']['total'] / m['seconds']:.1f}")
        print(f"| {m['step']} | {m['mode']} | {m['seconds']:.2f} / {s['seconds']:.2f} | "
              f"{s['seconds'] / m['seconds']:.1f}× | {m['tets']:,} / {s['tets']:,} | "
              f"{percent(m['nodes_unchanged'], m['nodes'])} / {percent(s['nodes_unchanged'], s['nodes'])} | "
              f"{m['quality']['meccano']['min']:.3f} / {s['quality']['meccano']['min']:.3f} | "
              f"{m['quality']['equilateral']['min']:.3f} / {s['quality']['equilateral']['min']:.3f} | "
              f"{m['quality']['min_dihedral_deg']:.1f}° / {s['quality']['min_dihedral_deg']:.1f}° | "
              f"{hxt_cells[0]} | {hxt_cells[1]} |")


def summary_row(name, moving, scratch, hxt):
    later = list(zip(moving[1:], scratch[1:]))
    moved = [(m, s) for m, s in later if m["mode"] == "moved"]
    speedups = sorted(s["seconds"] / m["seconds"] for m, s in moved)
    median = f"{speedups[len(speedups) // 2]:.1f}×" if speedups else "–"
    total = sum(s["seconds"] for _, s in later) / sum(m["seconds"] for m, _ in later)
    loss = max(max(s["quality"][k]["min"] - m["quality"][k]["min"] for k in ("meccano", "equilateral"))
               for m, s in later)
    unchanged = f'{100 * min(m["nodes_unchanged"] / m["nodes"] for m, _ in moved):.1f} %' if moved else "–"
    hxt_ratio = [hxt[m["step"]]["seconds"]["total"] / m["seconds"] for m in moving[1:]
                 if "seconds" in hxt.get(m["step"], {}) and m["mode"] == "moved"]
    print(f"| {name} | {len(moved)} of {len(later)} | {median} | {total:.1f}× | "
          f"{', '.join(f'{r:.1f}×' for r in hxt_ratio) or '–'} | {unchanged} | "
          f"{moving[-1]['tets'] / scratch[-1]['tets']:.3f} | {loss:+.3f} |")


def main(argv):
    quick = "--quick" in argv
    build = argv[argv.index("--build") + 1] if "--build" in argv else os.path.join(HERE, "..", "..", "build")
    work = argv[argv.index("--work") + 1] if "--work" in argv else "/tmp/bench-sequence"
    hxt_every = int(argv[argv.index("--hxt-every") + 1]) if "--hxt-every" in argv else 10
    cli = os.path.join(build, "module", "meccano-immerse")
    os.makedirs(work, exist_ok=True)
    count = 6 if quick else 21
    fault = argv[argv.index("--fault") + 1] if "--fault" in argv else DEFAULT_FAULT
    cases = {"patch_tilt": lambda: patch_steps(6, "tilt"), "patch_translate": lambda: patch_steps(count, "translate"),
             "fault_translate": lambda: fault_steps(fault, count, "translate"),
             "fault_rotate": lambda: fault_steps(fault, count, "rotate"),
             "fault_slide": lambda: fault_steps(fault, count, "slide"), "sphere_grow": lambda: sphere_steps(count)}
    if "--cases" in argv:
        cases = {name: cases[name] for name in argv[argv.index("--cases") + 1].split(",")}
    results = {}
    for name, make_case in cases.items():
        positions, triangles, box, resolution, extra = make_case()
        files = []
        for k, points in enumerate(positions):
            files.append(os.path.join(work, f"{name}_surface_{k}.obj"))
            write_obj(files[-1], points, triangles)
        moving = run_sequence(cli, files, box, resolution, extra, work, f"{name}_moving", False)
        scratch = run_sequence(cli, files, box, resolution, extra, work, f"{name}_anew", True)
        hxt = {k: run_hxt(build, cli, files[k], box, resolution, os.path.join(work, f"{name}_moving_{k}.msh"), work,
                          f"{name}_{k}")
               for k in sorted({*range(0, len(files), hxt_every), len(files) - 1})} \
            if hxt_every > 0 and name not in CLIPPED_CASES else {}
        results[name] = (moving, scratch, hxt)
        case_table(name, moving, scratch, hxt)
    print("\n### Summary\n")
    print("| case | steps moved | median speed-up of a moved step | speed-up of steps 1.. in all | HXT s ÷ module s "
          "(moved steps measured) | nodes unchanged, least of moved steps | tets at the last step ÷ anew "
          "| largest η min loss against anew |")
    print("|---|---|---|---|---|---|---|---|")
    for name, (moving, scratch, hxt) in results.items():
        summary_row(name, moving, scratch, hxt)


if __name__ == "__main__":
    main(sys.argv)
