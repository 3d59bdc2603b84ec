#!/usr/bin/env python3
"""The flux-jump problem on an inserted surface with dolfinx 0.5.2 (Debian 12's python3-dolfinx).

    -div grad u = 0 in the box,  u = 0 on the box sides (facet tags 1-6),  [du/dn] = 1 on S,

whose weak form puts S in the right-hand side only: g * avg(v) * dS(tag of S), an integral over the
interior facets tagged like S. The mesh is read the way that works in 0.5.2: gmsh.merge, then
gmshio.model_to_mesh (gmshio.read_from_msh fails there with NameError: msh). Facet tags are the
physical tags of the file: xmin ... zmax 1-6, interface_NAME 7, 8, ... (doc/user_guide.md, "Tags").

    flux_jump.py MESH.msh NAME [--compare REPORT.json]

prints the interface's area, the outflow -int grad u.n over the box sides and the solution's L2 norm.
With --compare, the report of `poisson_interface --mesh MESH.msh --interface NAME` (deal.II, P1, the same
discrete problem) must agree with them to 1e-6. Exit status 0 if every check holds, 1 otherwise.
"""
import argparse
import json
import logging
import sys

import gmsh
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem
from dolfinx.io import gmshio
from mpi4py import MPI
from petsc4py.PETSc import ScalarType

logging.getLogger().setLevel(logging.WARNING)  # FFCx logs every JIT compilation at INFO


def read_mesh(path, name):
    """The mesh, its facet tags, the tag of interface_NAME and S's area from the file's triangles."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.merge(path)
    tag = None
    for dim, group in gmsh.model.getPhysicalGroups(2):
        if gmsh.model.getPhysicalName(dim, group) == "interface_" + name:
            tag = group
    if tag is None:
        sys.exit(f"{path}: no 2D physical group interface_{name}")
    area = 0.0
    for entity in gmsh.model.getEntitiesForPhysicalGroup(2, tag):
        _, _, nodes = gmsh.model.mesh.getElements(2, entity)
        for triangle in np.asarray(nodes[0]).reshape(-1, 3):
            p = [gmsh.model.mesh.getNode(int(n))[0] for n in triangle]
            area += 0.5 * np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))
    mesh, _, facet_tags = gmshio.model_to_mesh(gmsh.model, MPI.COMM_WORLD, 0, gdim=3)
    gmsh.finalize()
    return mesh, facet_tags, tag, area


def solve(mesh, facet_tags, tag):
    V = fem.FunctionSpace(mesh, ("Lagrange", 1))
    box_facets = np.concatenate([facet_tags.find(side) for side in range(1, 7)])
    zero_on_box = fem.dirichletbc(ScalarType(0), fem.locate_dofs_topological(V, 2, box_facets), V)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dS = ufl.Measure("dS", domain=mesh, subdomain_data=facet_tags)
    a = ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx
    L = fem.Constant(mesh, ScalarType(1)) * ufl.avg(v) * dS(tag)
    problem = LinearProblem(a, L, bcs=[zero_on_box], petsc_options={"ksp_type": "preonly", "pc_type": "lu"})
    return problem.solve(), dS


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh")
    parser.add_argument("name")
    parser.add_argument("--compare", help="poisson_interface's --report of the same mesh and interface")
    args = parser.parse_args()

    mesh, facet_tags, tag, file_area = read_mesh(args.mesh, args.name)
    uh, dS = solve(mesh, facet_tags, tag)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
    n = ufl.FacetNormal(mesh)
    outflow = sum(fem.assemble_scalar(fem.form(-ufl.dot(ufl.grad(uh), n) * ds(side))) for side in range(1, 7))
    area = fem.assemble_scalar(fem.form(fem.Constant(mesh, ScalarType(1)) * dS(tag)))
    l2 = np.sqrt(fem.assemble_scalar(fem.form(uh * uh * ufl.dx)))
    print(f"interface_{args.name} (facet tag {tag}): area {area:.12g} (file: {file_area:.12g}); "
          f"outflow {outflow:.12g}; |u_h|_L2 {l2:.12g}")

    checks = [(abs(area - file_area) <= 1e-10 * file_area, "dS(tag) covers exactly the file's interface triangles"),
              (abs(outflow - area) <= 0.25 * area, "the outflow is within 25 % of the area")]
    if args.compare:
        with open(args.compare) as report_file:
            report = json.load(report_file)
        for key, mine, theirs in [("outflow", outflow, report["flux"]["outflow"]),
                                  ("L2 norm", l2, report["norms"]["l2"])]:
            checks.append((abs(mine - theirs) <= 1e-6 * abs(theirs), f"{key} equals deal.II's ({theirs:.12g})"))
    for passed, what in checks:
        print(("ok      " if passed else "FAILED  ") + what)
    return 0 if all(passed for passed, _ in checks) else 1


if __name__ == "__main__":
    sys.exit(main())
