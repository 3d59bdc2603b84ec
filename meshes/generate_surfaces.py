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
inclusion_sphere.obj  the demo solver's inclusion: the sphere of radius 0.3 centred at (0.5, 0.5, 0.5),
                   a closed surface, the octahedron |x| + |y| + |z| = 1 with (N/2)^2 triangles per face
                   pushed onto it (as meccano::triangulate_star_shaped), normals out.

With --hard, instead: the hard surfaces of tests/data/hard_surfaces, which reproduce what makes real
faults hard, in their units (UTM-like metres, x about 5e5, y about 3.8e6, z from -12 km to +1 km),
each an open disk of at most a few thousand triangles, the same at every run (fixed seeds):

creased.obj        a steep fault folded along three crease lines (10, 25 and 40 degrees), ~1 km triangles
multiscale.obj     a gently curved fault whose triangles run from a few metres to a few kilometres
thin_long.obj      a 40 km x 4 km strip (aspect 10:1), curved along strike and twisted
low_dip.obj        a thrust dipping 5-10 degrees, undulating, 20 km along strike
vertical.obj       an exactly vertical fault (dip 90 degrees) striking 30 degrees off the x axis, curved
thin_tail.obj      a steep fault 60 km long whose last 17 km are a tail 1.2-1.5 km deep (as Western Santa
                   Cruz Island's east end), narrower than V_M's cubes at l_r = E/30
sharp_tip.obj      a fault 40 km long tapering to a 10 degree tip, narrower than V_M's cubes near it at any l_r

Usage: generate_surfaces.py [--output-dir DIR] [N]   (default N = 48, DIR = the current folder)
       generate_surfaces.py --hard [--output-dir DIR]   (the committed ones: DIR = tests/data/hard_surfaces)
"""
import argparse
import math
import os
import random
import textwrap


def write_obj(path, points, triangles, comment):
    with open(path, "w") as out:
        out.writelines(f"# {line}\n" for line in comment.splitlines())
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


def octahedral_sphere(place, n):
    """The octahedron |x| + |y| + |z| = 1 with n^2 triangles per face, each point q mapped by
    place(q / |q|), normals out of the octahedron; the points in the order meccano::triangulate_star_shaped
    numbers them, so that the two agree. (tests/bench/closed_surfaces.py uses it too.)"""
    index, points, triangles = {}, [], []

    def point(q):
        if q not in index:
            index[q] = len(points)
            r = math.sqrt(sum(c * c for c in q))
            points.append(place(tuple(c / r for c in q)))
        return index[q]

    for face in range(8):
        s = (-1 if face & 1 else 1, -1 if face & 2 else 1, -1 if face & 4 else 1)

        def corner(a, b):
            return (s[0] * a, s[1] * b, s[2] * (n - a - b))

        def add_triangle(p, q, r):
            # Out of the octahedron, decided on the octahedron itself (a turned ellipsoid's normals are
            # not along s).
            u, v = tuple(x - y for x, y in zip(q, p)), tuple(x - y for x, y in zip(r, p))
            if sum(c * k for c, k in zip(cross(u, v), s)) < 0:
                q, r = r, q
            triangles.append((point(p), point(q), point(r)))

        for a in range(n):
            for b in range(n - a):
                add_triangle(corner(a, b), corner(a + 1, b), corner(a, b + 1))
                if a + b + 2 <= n:
                    add_triangle(corner(a + 1, b), corner(a + 1, b + 1), corner(a, b + 1))
    return points, triangles


def inclusion_sphere(n):
    centre, radius = (0.5, 0.5, 0.5), 0.3
    return octahedral_sphere(lambda d: tuple(c + radius * k for c, k in zip(centre, d)), n)


# ------------------------------------------------------------------------------------------------
# Hard surfaces: fault-like disks in UTM-like metres (tests/data/hard_surfaces). Strike directions are
# angles counterclockwise from the x axis; each surface dips to the left of its strike direction and is
# triangulated counterclockwise in its (along strike, down dip) parameters.

Z = (0.0, 0.0, 1.0)


def add(*vectors):
    return tuple(sum(components) for components in zip(*vectors))


def scaled(v, s):
    return tuple(s * c for c in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def horizontal(azimuth):
    """The horizontal unit vector at `azimuth` radians counterclockwise from the x axis."""
    return (math.cos(azimuth), math.sin(azimuth), 0.0)


def down_dip(azimuth, dip):
    """The unit vector down the dip of a plane striking at `azimuth` and dipping `dip` radians to its left."""
    return add(scaled(horizontal(azimuth + math.pi / 2), math.cos(dip)), scaled(Z, -math.sin(dip)))


def arc_trace(s, length, heading0, heading1):
    """The point at arc length s of a horizontal circular arc from the origin whose heading turns from
    heading0 to heading1 (radians) over `length` (a straight line if they are equal)."""
    if heading0 == heading1:
        return scaled(horizontal(heading0), s)
    curvature = (heading1 - heading0) / length
    heading = heading0 + curvature * s
    return ((math.sin(heading) - math.sin(heading0)) / curvature, (math.cos(heading0) - math.cos(heading)) / curvature, 0.0)


def jittered_grid(columns, rows, seed, jitter=0.3, fixed_columns=(), straight_columns=False):
    """(u, v) nodes of a columns x rows grid of unit cells, row by row, each moved at random (seeded) by
    up to `jitter` on each axis: corners stay, rim nodes move along their rim, nodes of `fixed_columns`
    along v only; with `straight_columns` a column's nodes all move by the same u."""
    rng = random.Random(seed)
    fixed = {0, columns, *fixed_columns}
    shift = [0.0 if i in fixed else rng.uniform(-jitter, jitter) for i in range(columns + 1)]
    nodes = []
    for j in range(rows + 1):
        for i in range(columns + 1):
            du = shift[i] if straight_columns or i in fixed else rng.uniform(-jitter, jitter)
            nodes.append((i + du, j + (0.0 if j in (0, rows) else rng.uniform(-jitter, jitter))))
    return nodes


def grid_triangles(points, columns, rows):
    """Two triangles per cell of a (columns + 1) x (rows + 1) grid of points (row by row), cut along the
    cell's shorter diagonal, counterclockwise in the grid's (u, v)."""
    triangles = []
    for j in range(rows):
        for i in range(columns):
            a, b = j * (columns + 1) + i, j * (columns + 1) + i + 1
            c, d = b + columns + 1, a + columns + 1
            if math.dist(points[a], points[c]) <= math.dist(points[b], points[d]):
                triangles += [(a, b, c), (a, c, d)]
            else:
                triangles += [(a, b, d), (b, c, d)]
    return triangles


def creased():
    """20 km along strike, 12 km down a 70 degree dip, folded along three down-dip crease lines 4, 9
    and 15 km along, where the top trace turns about the down-dip direction by +10, -25 and +40 degrees
    (the angles between the planes on either side); planar between them; 1 km jittered cells, the
    creases along cell edges."""
    columns, rows, cell = 20, 12, 1000.0
    turns = {4: 10.0, 9: -25.0, 15: 40.0}
    strike, dip = math.radians(20), math.radians(70)
    d = down_dip(strike, dip)
    # The top trace: straight within a panel, turned about d at each crease.
    starts, point, direction = [], (0.0, 0.0, 0.0), horizontal(strike)
    for column in range(columns):
        if column in turns:
            angle = math.radians(turns[column])
            direction = add(scaled(direction, math.cos(angle)), scaled(cross(d, direction), math.sin(angle)))
        starts.append((point, direction))
        point = add(point, scaled(direction, cell))

    def trace(u):
        start, direction = starts[min(int(u), columns - 1)]
        return add(start, scaled(direction, (u - min(int(u), columns - 1)) * cell))

    origin = (512000.0, 3801500.0, 600.0)
    points = [add(origin, trace(u), scaled(d, v * cell))
              for u, v in jittered_grid(columns, rows, seed=1, fixed_columns=turns)]
    return points, grid_triangles(points, columns, rows)


def thin_long():
    """A 40 km x 4 km strip (aspect 10:1): its top trace a horizontal arc whose strike turns from 55 to
    68 degrees off the x axis, its dip twisting from 62 to 85 degrees along it; 800 m jittered cells."""
    columns, rows, cell = 50, 5, 800.0
    length, width = columns * cell, rows * cell
    heading0, heading1 = math.radians(55), math.radians(68)
    origin = (498000.0, 3772000.0, 400.0)
    points = []
    for u, v in jittered_grid(columns, rows, seed=2):
        s = u * cell
        heading = heading0 + (heading1 - heading0) * s / length
        dip = math.radians(62 + 23 * s / length)
        points.append(add(origin, arc_trace(s, length, heading0, heading1), scaled(down_dip(heading, dip), v * width / rows)))
    return points, grid_triangles(points, columns, rows)


def low_dip():
    """A thrust 20 km along a strike 110 degrees off the x axis and 14 km down a 7.5 degree dip,
    undulating by up to 100 m (wavelengths 5-11 km) so that its dip varies between about 5 and 10
    degrees (4.3 to 11.8 in single triangles); 1 km jittered cells."""
    columns, rows, cell = 20, 14, 1000.0
    strike, dip = math.radians(110), math.radians(7.5)
    along, across = horizontal(strike), horizontal(strike + math.pi / 2)
    origin = (541000.0, 3826000.0, -3500.0)
    points = []
    for u, v in jittered_grid(columns, rows, seed=3):
        s, w = u * cell, v * cell
        z = (-w * math.tan(dip) + 60 * math.sin(2 * math.pi * s / 9000) * math.sin(2 * math.pi * w / 11000)
             + 40 * math.cos(2 * math.pi * (s - 0.6 * w) / 5000))
        points.append(add(origin, scaled(along, s), scaled(across, w), scaled(Z, z)))
    return points, grid_triangles(points, columns, rows)


def vertical():
    """An exactly vertical surface (dip 90 degrees), 20 km along a horizontal arc whose strike turns
    from 18 to 42 degrees off the x axis (30 on average), from 500 m above to 11.5 km below sea
    level; 1 km jittered cells whose columns stay vertical lines, so every triangle has a vertical
    edge and lies in a vertical plane."""
    columns, rows, cell = 20, 12, 1000.0
    length = columns * cell
    origin = (523000.0, 3789000.0, 500.0)
    points = [add(origin, arc_trace(u * cell, length, math.radians(18), math.radians(42)), (0.0, 0.0, -v * cell))
              for u, v in jittered_grid(columns, rows, seed=4, straight_columns=True)]
    return points, grid_triangles(points, columns, rows)


def thin_tail():
    """A fault 60 km along a strike that turns from 80 to 95 degrees off the x axis, dipping 75 degrees,
    whose lower edge rises from 8 km below its top trace to 1.5 km over 3 km, 40 km along, then to 1.2 km
    at its east end: a tail 17 km long and narrower than V_M's cubes at E/30, as the east end of the
    Western Santa Cruz Island fault is; 1 km jittered cells along strike, 12 rows down dip (cells of
    the tail about 120 m deep)."""
    columns, rows, cell = 60, 12, 1000.0
    length = columns * cell
    heading0, heading1 = math.radians(80), math.radians(95)
    origin = (176000.0, 3772000.0, -60.0)

    def depth(s):
        if s <= 40000.0:
            return 8000.0
        if s <= 43000.0:
            return 8000.0 - 6500.0 * (s - 40000.0) / 3000.0
        return 1500.0 - 300.0 * (s - 43000.0) / (length - 43000.0)

    points = []
    for u, v in jittered_grid(columns, rows, seed=6, fixed_columns=(40, 43)):
        s = u * cell
        heading = heading0 + (heading1 - heading0) * s / length
        points.append(add(origin, arc_trace(s, length, heading0, heading1),
                          scaled(down_dip(heading, math.radians(75)), v * depth(s) / rows / math.sin(math.radians(75)))))
    return points, grid_triangles(points, columns, rows)


def sharp_tip():
    """A fault 40 km along strike (the x axis), dipping 60 degrees, bowed by 300 m, whose width down dip
    shrinks linearly from 7 km to a 10 degree tip at its east end: near the tip it is narrower than
    V_M's cubes at any l_r, so S_M stops short of it by a few l_r on one side of S; 1 km columns of 8
    cells each, the last one a fan into the tip."""
    columns, rows, length = 40, 8, 40000.0
    half_angle = math.radians(5)
    dip = math.radians(60)
    origin = (500000.0, 3800000.0, -4000.0)

    def point(s, t):
        return add(origin, (s, t * math.cos(dip) + 300 * math.sin(math.pi * s / length), -t * math.sin(dip)))

    points = []
    for i in range(columns):
        s = length * i / columns
        width = 2 * (length - s) * math.tan(half_angle)
        points += [point(s, (j / rows - 0.5) * width) for j in range(rows + 1)]
    tip = len(points)
    points.append(point(length, 0.0))
    triangles = []
    for i in range(columns - 1):
        for j in range(rows):
            a, d = i * (rows + 1) + j, i * (rows + 1) + j + 1
            b, c = a + rows + 1, d + rows + 1
            triangles += [(a, b, c), (a, c, d)]
    last = (columns - 1) * (rows + 1)
    triangles += [(last + j, tip, last + j + 1) for j in range(rows)]
    return points, triangles


def newest_vertex_bisection(points, triangles, too_large):
    """Refines a conforming triangulation by newest-vertex bisection until no triangle is too_large(its
    three points). Each triangle (a, b, c) is cut at the midpoint m of its refinement edge a-b into
    (c, a, m) and (b, c, m), keeping its orientation, together with its neighbour across a-b, which is
    refined first until a-b is its refinement edge too; every edge of the input must be the refinement
    edge of both its triangles or of neither (a grid of squares cut along diagonals, the diagonals
    first, is such). Returns the points (input first) and the triangles."""
    points, triangles = list(points), [tuple(t) for t in triangles]
    alive = [True] * len(triangles)
    owner = {(t[k], t[(k + 1) % 3]): index for index, t in enumerate(triangles) for k in range(3)}
    midpoints = {}

    def split(index, m):
        a, b, c = triangles[index]
        alive[index] = False
        for k in range(3):
            del owner[(triangles[index][k], triangles[index][(k + 1) % 3])]
        for child in ((c, a, m), (b, c, m)):
            owner.update({(child[k], child[(k + 1) % 3]): len(triangles) for k in range(3)})
            triangles.append(child)
            alive.append(True)

    def refine(index):
        a, b, _ = triangles[index]
        while (b, a) in owner and triangles[owner[(b, a)]][:2] != (b, a):
            refine(owner[(b, a)])
        neighbour = owner.get((b, a))
        key = (min(a, b), max(a, b))
        if key not in midpoints:
            midpoints[key] = len(points)
            points.append(scaled(add(points[a], points[b]), 0.5))
        split(index, midpoints[key])
        if neighbour is not None:
            split(neighbour, midpoints[key])

    index = 0
    while index < len(triangles):
        if alive[index] and too_large([points[v] for v in triangles[index]]):
            refine(index)
        index += 1
    return points, [t for t, kept in zip(triangles, alive) if kept]


def multiscale():
    """A gently curved surface 16 km along strike and 10 km down a dip steepening from 40 to 55 degrees
    (listric), bowed by 600 m along strike: right isosceles triangles of 2 km legs refined by newest-
    vertex bisection towards a point, to hypotenuses of 5 m + 0.35 x the distance (triangles from
    about 4 m to 2.8 km, every angle near 45 or 90 degrees in (s, w)), then the inner nodes jittered by
    up to a tenth of their shortest edge."""
    columns, rows, cell = 8, 5, 2000.0
    length = columns * cell
    grid = [(i * cell, j * cell) for j in range(rows + 1) for i in range(columns + 1)]
    triangles = []
    for j in range(rows):
        for i in range(columns):
            a, b = j * (columns + 1) + i, j * (columns + 1) + i + 1
            c, d = b + columns + 1, a + columns + 1
            # Refinement edge (the diagonal) first; counterclockwise.
            triangles += [(a, c, d), (c, a, b)] if (i + j) % 2 == 0 else [(b, d, a), (d, b, c)]
    focus = (5300.0, 6100.0)
    parameters, triangles = newest_vertex_bisection(
        grid, triangles, lambda p: math.dist(p[0], p[1]) > 5 + 0.35 * math.dist(focus, scaled(add(*p), 1 / 3)))

    rng = random.Random(5)
    shortest = {}
    for t in triangles:
        for k in range(3):
            a, b = t[k], t[(k + 1) % 3]
            edge = math.dist(parameters[a], parameters[b])
            shortest[a] = min(shortest.get(a, edge), edge)
    jittered = [(s, w) if s in (0, length) or w in (0, rows * cell)
                else (s + rng.uniform(-0.1, 0.1) * shortest[n], w + rng.uniform(-0.1, 0.1) * shortest[n])
                for n, (s, w) in enumerate(parameters)]

    strike, dip0, dip1 = math.radians(-35), math.radians(40), math.radians(55)
    along, across = horizontal(strike), horizontal(strike + math.pi / 2)
    rate = (dip1 - dip0) / (rows * cell)
    origin = (487000.0, 3794000.0, 0.0)

    def surface_point(s, w):
        bow = 600 * (1 - (2 * s / length - 1) ** 2)
        dip = dip0 + rate * w
        return add(origin, scaled(along, s), scaled(across, bow + (math.sin(dip) - math.sin(dip0)) / rate),
                   scaled(Z, (math.cos(dip) - math.cos(dip0)) / rate))

    return [surface_point(s, w) for s, w in jittered], triangles


HARD_SURFACES = {"creased": creased, "multiscale": multiscale, "thin_long": thin_long, "low_dip": low_dip,
                 "vertical": vertical, "thin_tail": thin_tail, "sharp_tip": sharp_tip}


def main():
    parser = argparse.ArgumentParser(
        description="Writes cube_example.obj, spherical_cap.obj and inclusion_sphere.obj, or the hard surfaces.")
    parser.add_argument("n", nargs="?", type=int, default=48,
                        help="grid resolution N (the cap gets N // 2 rings, the sphere N // 2 cells per octant edge)")
    parser.add_argument("--hard", action="store_true", help="write the hard surfaces of tests/data/hard_surfaces instead")
    parser.add_argument("--output-dir", default=".", help="folder to write into (created if missing)")
    args = parser.parse_args()
    if args.n < 2:
        parser.error(f"N must be at least 2 (got {args.n})")
    os.makedirs(args.output_dir, exist_ok=True)
    n, path = args.n, lambda name: os.path.join(args.output_dir, name)
    if args.hard:
        for name, make in HARD_SURFACES.items():
            write_obj(path(f"{name}.obj"), *make(),
                      f"{name} (meshes/generate_surfaces.py --hard):\n" + textwrap.fill(" ".join(make.__doc__.split()), 100))
        return
    write_obj(path("cube_example.obj"), *cube_example(n), f"cube example patch, {n} x {n} grid (generate_surfaces.py)")
    write_obj(path("spherical_cap.obj"), *spherical_cap(n // 2), f"spherical cap, {n // 2} rings (generate_surfaces.py)")
    write_obj(path("inclusion_sphere.obj"), *inclusion_sphere(n // 2),
              f"inclusion sphere, {n // 2} cells per octant edge (generate_surfaces.py)")


if __name__ == "__main__":
    main()
