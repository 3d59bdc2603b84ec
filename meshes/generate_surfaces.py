#!/usr/bin/env python3
"""Writes the immersed surfaces used by the demos, as OBJ files in the current folder (meshes/ for the
committed ones) or in --output-dir.

cube_example.obj   the paper-like patch of the cube example: over (x, y) in [0.2, 0.8]^2,
                   z = 0.42 + 0.12 u v + 0.10 sin(pi u) sin(pi v), u = (x - 0.2)/0.6, v = (y - 0.2)/0.6,
                   a smooth curved open patch well inside the unit cube (0.2 from every face, rim
                   height 0.42..0.54, peak about 0.55), triangulated on a regular N x N grid with
                   alternating diagonals, normals towards +z.
spherical_cap.obj  a cap of the sphere of radius 0.4 centred at (0.5, 0.5, 0.2), polar angle up to 65
                   degrees: a circular rim, no natural corners.

Usage: generate_surfaces.py [--output-dir DIR] [N]   (default N = 48, DIR = the current folder)
"""
import argparse
import math
import os


def write_obj(path, points, triangles, comment):
    with open(path, "w") as out:
        out.write(f"# {comment}\n")
        for p in points:
            out.write("v %.17g %.17g %.17g\n" % p)
        for a, b, c in triangles:
            out.write(f"f {a + 1} {b + 1} {c + 1}\n")


def cube_example(n):
    points, triangles = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            u, v = i / n, j / n
            z = 0.42 + 0.12 * u * v + 0.10 * math.sin(math.pi * u) * math.sin(math.pi * v)
            points.append((0.2 + 0.6 * u, 0.2 + 0.6 * v, z))
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i
            triangles += [(a, b, c), (a, c, d)] if (i + j) % 2 == 0 else [(a, b, d), (b, c, d)]
    return points, triangles


def spherical_cap(rings):
    centre, radius, opening = (0.5, 0.5, 0.2), 0.4, math.radians(65)
    points, triangles = [(centre[0], centre[1], centre[2] + radius)], []
    previous = [0]
    for r in range(1, rings + 1):
        theta = opening * r / rings
        count = 6 * r
        ring = []
        for k in range(count):
            phi = 2 * math.pi * k / count
            ring.append(len(points))
            points.append((centre[0] + radius * math.sin(theta) * math.cos(phi),
                           centre[1] + radius * math.sin(theta) * math.sin(phi),
                           centre[2] + radius * math.cos(theta)))
        # Stitch the previous ring (6(r-1) points) to this one (6r points), sector by sector.
        for sector in range(6):
            for k in range(r):
                outer = ring[sector * r + k]
                outer_next = ring[(sector * r + k + 1) % count]
                inner = previous[(sector * (r - 1) + k) % len(previous)] if r > 1 else 0
                triangles.append((inner, outer, outer_next))
                if k < r - 1:
                    inner_next = previous[(sector * (r - 1) + k + 1) % len(previous)]
                    triangles.append((inner, outer_next, inner_next))
        previous = ring
    return points, triangles


def main():
    parser = argparse.ArgumentParser(description="Writes cube_example.obj and spherical_cap.obj.")
    parser.add_argument("n", nargs="?", type=int, default=48, help="grid resolution N (the cap gets N // 2 rings)")
    parser.add_argument("--output-dir", default=".", help="folder to write into (created if missing)")
    args = parser.parse_args()
    if args.n < 2:
        parser.error(f"N must be at least 2 (got {args.n})")
    os.makedirs(args.output_dir, exist_ok=True)
    n, path = args.n, lambda name: os.path.join(args.output_dir, name)
    write_obj(path("cube_example.obj"), *cube_example(n), f"cube example patch, {n} x {n} grid (generate_surfaces.py)")
    write_obj(path("spherical_cap.obj"), *spherical_cap(n // 2), f"spherical cap, {n // 2} rings (generate_surfaces.py)")


if __name__ == "__main__":
    main()
