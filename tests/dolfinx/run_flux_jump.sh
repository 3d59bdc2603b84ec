#!/usr/bin/env bash
# The user guide's dolfinx example as a test: meccano-immerse meshes the spherical cap, dolfinx solves
# the flux-jump problem on it (flux_jump.py) and, when the deal.II demo is built, compares with it.
#
#   run_flux_jump.sh WORK MECCANO_IMMERSE [POISSON_INTERFACE]
#
# Exit status 77 (CTest: skipped) with a message when python3-dolfinx or python3-gmsh is missing.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: run_flux_jump.sh WORK MECCANO_IMMERSE [POISSON_INTERFACE]" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
work=$1
python=/usr/bin/python3
if ! "$python" -c "import dolfinx, gmsh" 2>/dev/null; then
  echo "skipped: dolfinx or gmsh is not importable by $python (apt-get install python3-dolfinx python3-gmsh)"
  exit 77
fi
rm -rf "$work" && mkdir -p "$work"
"$2" --box 0,0,0,1,1,1 --level 1 --surface "$here/../../meshes/spherical_cap.obj:cap" --resolution 0.08 --quiet \
  --output "$work/cap.msh"
compare=()
if [ $# -ge 3 ] && [ -n "$3" ]; then
  "$3" --mesh "$work/cap.msh" --interface cap --report "$work/deal.ii.json" > /dev/null
  compare=(--compare "$work/deal.ii.json")
fi
"$python" "$here/flux_jump.py" "$work/cap.msh" cap "${compare[@]}"
