#!/usr/bin/python3
"""Renders groups of a meccano-immerse MSH 4.1 ASCII file to a PNG, for inspecting stage outputs.

Usage: plot_msh.py MESH.msh OUT.png [--volume GROUP ...] [--surface GROUP ...] [--obj S.obj] [--title T]

--volume GROUP   draws the boundary of a 3D group (e.g. volumetric_1), shaded
--surface GROUP  draws a 2D group (e.g. interface_1)
--obj S.obj      draws an immersed surface from an OBJ file, as a red wireframe
Needs Debian's python3-matplotlib (installed by scripts/setup.sh); runs with /usr/bin/python3.
"""
import argparse
import collections

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402


def read_msh41(path):
    """Nodes, physical names, and the elements of each physical group (by name)."""
    with open(path) as f:
        lines = [line.strip() for line in f]
    i = 0
    names, entity_groups = {}, {}
    nodes, groups = {}, collections.defaultdict(list)
    while i < len(lines):
        section = lines[i]
        if section == "$PhysicalNames":
            for k in range(int(lines[i + 1])):
                dim, tag, name = lines[i + 2 + k].split(maxsplit=2)
                names[(int(dim), int(tag))] = name.strip('"')
        elif section == "$Entities":
            counts = [int(c) for c in lines[i + 1].split()]
            row = i + 2
            for dim, count in enumerate(counts):
                for _ in range(count):
                    fields = lines[row].split()
                    tag = int(fields[0])
                    first = 4 if dim == 0 else 7
                    physical = [int(x) for x in fields[first + 1:first + 1 + int(fields[first])]]
                    entity_groups[(dim, tag)] = [names[(dim, p)] for p in physical if (dim, p) in names]
                    row += 1
        elif section == "$Nodes":
            blocks = int(lines[i + 1].split()[0])
            row = i + 2
            for _ in range(blocks):
                count = int(lines[row].split()[3])
                tags = [int(t) for t in lines[row + 1:row + 1 + count]]
                for k, tag in enumerate(tags):
                    nodes[tag] = [float(c) for c in lines[row + 1 + count + k].split()[:3]]
                row += 1 + 2 * count
        elif section == "$Elements":
            blocks = int(lines[i + 1].split()[0])
            row = i + 2
            for _ in range(blocks):
                dim, tag, _, count = (int(x) for x in lines[row].split())
                elements = [[int(n) for n in lines[row + 1 + k].split()[1:]] for k in range(count)]
                for name in entity_groups.get((dim, tag), []):
                    groups[name].extend(elements)
                row += 1 + count
        i += 1
    return nodes, groups


def boundary_faces(tets):
    count = collections.Counter()
    oriented = {}
    for a, b, c, d in tets:
        for face in ((b, c, d), (a, d, c), (a, b, d), (a, c, b)):
            key = tuple(sorted(face))
            count[key] += 1
            oriented[key] = face
    return [oriented[k] for k, n in count.items() if n == 1]


def read_obj(path):
    points, triangles = [], []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if fields and fields[0] == "v":
                points.append([float(x) for x in fields[1:4]])
            elif fields and fields[0] == "f":
                triangles.append([int(x.split("/")[0]) - 1 for x in fields[1:4]])
    return np.array(points), triangles


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mesh")
    parser.add_argument("png")
    parser.add_argument("--volume", action="append", default=[])
    parser.add_argument("--surface", action="append", default=[])
    parser.add_argument("--obj")
    parser.add_argument("--title", default="")
    parser.add_argument("--view", default="28,-60", help="elevation,azimuth in degrees")
    args = parser.parse_args()

    nodes, groups = read_msh41(args.mesh)
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    colours = ["#9ecae1", "#a1d99b", "#fdd0a2", "#dadaeb"]
    for k, name in enumerate(args.volume + args.surface):
        faces = boundary_faces(groups[name]) if name in args.volume else groups[name]
        polygons = [[nodes[n] for n in face] for face in faces]
        ax.add_collection3d(Poly3DCollection(polygons, facecolor=colours[k % len(colours)], edgecolor="#555555",
                                             linewidth=0.15, alpha=0.9))
    if args.obj:
        points, triangles = read_obj(args.obj)
        edges = {tuple(sorted((t[i], t[(i + 1) % 3]))) for t in triangles for i in range(3)}
        ax.add_collection3d(Line3DCollection([[points[a], points[b]] for a, b in edges], colors="#d62728",
                                             linewidths=0.3))
    coordinates = np.array(list(nodes.values()))
    lo, hi = coordinates.min(axis=0), coordinates.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    elevation, azimuth = (float(a) for a in args.view.split(","))
    ax.view_init(elev=elevation, azim=azimuth)
    ax.set_title(args.title)
    fig.tight_layout()
    fig.savefig(args.png, dpi=130)


if __name__ == "__main__":
    main()
