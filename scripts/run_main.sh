#!/usr/bin/env bash
# The main job: set up the machine, build, and run the paper's cube example through the whole method.
# Inserts meshes/cube_example.obj (a smooth curved patch inside the unit cube, made by meshes/generate_surfaces.py)
# into the unit-cube meccano mesh at l_r = 0.03 with all four steps, and writes to out/:
#   cube_example.msh                the result: untangled, smoothed, S_M tagged as interface_patch
#   cube_example_report.json        timings, counts and quality before and after smoothing
#   cube_example_quality.csv/.png   quality histograms before and after smoothing (the paper's Figure 6)
#   cube_example_approximation.*    step 2 for inspection: the healed S_M before projection (and a picture)
#   cube_example_projection.msh     step 3 for inspection: S_M projected onto S, tets still tangled
#   convergence_p1.csv, convergence.png   the demo solver's small convergence study
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
mkdir -p out
cli=build/module/meccano-immerse
example=(--box 0,0,0,1,1,1 --surface meshes/cube_example.obj:patch --resolution 0.03)

"$cli" "${example[@]}" --output out/cube_example.msh --report out/cube_example_report.json \
  --histograms out/cube_example_quality.csv
/usr/bin/python3 scripts/plot_quality.py out/cube_example_quality.csv out/cube_example_quality.png \
  --title "cube example, l_r = 0.03: quality before and after SUS"

"$cli" "${example[@]}" --quiet --stage approximation --output out/cube_example_approximation.msh
"$cli" "${example[@]}" --quiet --stage projection --output out/cube_example_projection.msh
/usr/bin/python3 scripts/plot_msh.py out/cube_example_approximation.msh out/cube_example_approximation.png \
  --surface interface_patch --view 35,-70 --title "cube example: healed S_M, l_r = 0.03"

/usr/bin/python3 - <<'EOF'
import json
r = json.load(open("out/cube_example_report.json"))
q = r["quality"]["after_smoothing"]
print(f"cube example: {r['tets']} tets, {r['nodes']} nodes, {r['inverted']} inverted after SUS")
print(f"  mean ratio against meccano:     min {q['meccano']['min']:.3f}  mean {q['meccano']['mean']:.3f}")
print(f"  mean ratio against equilateral: min {q['equilateral']['min']:.3f}  mean {q['equilateral']['mean']:.3f}")
print(f"  dihedral angles {r['min_dihedral_deg']:.1f}° to {r['max_dihedral_deg']:.1f}°; {r['seconds']['total']:.2f} s in all")
EOF
# The deal.II demo (doc/solver.md): a Neumann (flux-jump) condition on the cube example's surface, on
# the mesh above and in a small convergence study (3 levels, P1, up to about 470 k tets).
if [ -x build/solver_demo/poisson_interface ]; then
  build/solver_demo/poisson_interface --mesh out/cube_example.msh --interface patch --degree 1
  build/solver_demo/convergence_study --levels 3 --degree 1 --csv out/convergence_p1.csv
  /usr/bin/python3 scripts/plot_convergence.py out/convergence.png P1=out/convergence_p1.csv
else
  echo "main job: deal.II not found, the demo solver was not built"
fi
echo "main job: done; open out/*.msh in Gmsh, out/*.png in an image viewer"
