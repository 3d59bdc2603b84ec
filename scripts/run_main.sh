#!/usr/bin/env bash
# The main job: set up the machine, build, and run the demo.
# Builds the meccano mesh of the unit cube, then runs the stages implemented so far on the paper's cube
# example (meshes/cube_example.obj): the mesh with V_M and the healed S_M (and a picture of it), and the
# mesh with S_M projected onto the surface (tangled: smoothing is not implemented yet).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
mkdir -p out
build/module/meccano-immerse --box 0,0,0,1,1,1 --level 12 --output out/cube_meccano.msh
build/module/meccano-immerse --box 0,0,0,1,1,1 --surface meshes/cube_example.obj:patch --resolution 0.03 \
  --stage approximation --output out/cube_example_approximation.msh
build/module/meccano-immerse --box 0,0,0,1,1,1 --surface meshes/cube_example.obj:patch --resolution 0.03 \
  --stage projection --output out/cube_example_projection.msh
/usr/bin/python3 scripts/plot_msh.py out/cube_example_approximation.msh out/cube_example_approximation.png \
  --surface interface_patch --view 35,-70 --title "cube example: healed S_M, l_r = 0.03"
echo "main job: done; open out/*.msh in Gmsh, out/*.png in an image viewer"
