#!/usr/bin/env bash
# The main job: set up the machine, build, and run the demo.
# Builds the meccano mesh of the unit cube (level 12: 24 576 tets) and writes out/cube_meccano.msh.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
mkdir -p out
build/module/meccano-immerse --box 0,0,0,1,1,1 --level 12 --output out/cube_meccano.msh
echo "main job: done; open out/cube_meccano.msh in Gmsh"
