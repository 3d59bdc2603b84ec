#!/usr/bin/env bash
# The whole insertion against Gmsh HXT, side by side in one run (issue 6's speed target).
#
# For each l_r, meccano-immerse inserts the cube example (meshes/cube_example.obj) into the unit-cube
# meccano with SUS over the whole mesh and over a 3-ring band; reference-gmsh builds the unit cube with
# the same surface embedded (HXT) at sizes H chosen to bracket the module's tet counts. HXT's time at
# the module's tet count is interpolated (log-log) between its two nearest runs, so the ratio compares
# meshes of the same size. Seconds are the tools' own "total" (reading the surface, meshing or
# inserting, the quality pass; not the MSH write); peak RSS from /usr/bin/time. Prints a Markdown table.
# The interpolation is compare_references.py's; compare_references.sh is the wider comparison (TetGen,
# Gmsh Delaunay, more surfaces, the solver, a moving surface: doc/comparison.md).
#
# Usage: tests/bench/compare_gmsh.sh [--threads N] [L ...]   (default l_r: 0.03125 0.015625 0.0078125;
#        Gmsh sizes: 0.05 0.035 0.025 0.018 0.0125). Run after scripts/build.sh, from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
threads=$(nproc)
if [ "${1:-}" = "--threads" ]; then threads=$2; shift 2; fi
[ $# -gt 0 ] && resolutions=("$@") || resolutions=(0.03125 0.015625 0.0078125)
sizes=(0.05 0.035 0.025 0.018 0.0125)
cli=build/module/meccano-immerse
gmsh_tool=build/reference/reference-gmsh
[ -x "$cli" ] && [ -x "$gmsh_tool" ] || { echo "compare_gmsh: build first (scripts/build.sh; reference-gmsh needs libgmsh-dev)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
surface=meshes/cube_example.obj:patch

rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
for l in "${resolutions[@]}"; do
  for mode in whole band; do
    /usr/bin/time -v "$cli" --box 0,0,0,1,1,1 --surface "$surface" --resolution "$l" --smoothing "$mode" \
      --threads "$threads" --quiet --output "$work/m.msh" --report "$work/meccano_${l}_${mode}.json" 2> "$work/time"
    rss "$work/time" > "$work/meccano_${l}_${mode}.rss"
    echo "meccano-immerse l_r $l $mode: done" >&2
  done
done
for h in "${sizes[@]}"; do
  /usr/bin/time -v "$gmsh_tool" --box 0 0 0 1 1 1 --surface "$surface" --size "$h" --algorithm hxt \
    --threads "$threads" --quiet --output "$work/g.msh" --report "$work/gmsh_${h}.json" 2> "$work/time"
  rss "$work/time" > "$work/gmsh_${h}.rss"
  echo "reference-gmsh H $h: done" >&2
done

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(date -u +%F), $threads threads"
echo
/usr/bin/python3 - "$work" "${resolutions[*]}" "${sizes[*]}" <<'EOF'
import json, sys
sys.path.insert(0, "tests/bench")
from compare_references import loglog_interpolate
work, resolutions, sizes = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
load = lambda name: (json.load(open(f"{work}/{name}.json")), int(open(f"{work}/{name}.rss").read()) / 1024)
gmsh = sorted((load(f"gmsh_{h}") + (h,) for h in sizes), key=lambda g: g[0]["tets"])

def hxt_seconds(tets):
    """HXT's total seconds at `tets`, interpolated in log-log between its two nearest runs."""
    return loglog_interpolate([(report["tets"], report["seconds"]["total"]) for report, _, _ in gmsh], tets)[0]

print("| mesh | tets | seconds | k tets/s | HXT s at these tets | HXT ÷ this | η min | η mean | min dih. | max dih. | peak RSS |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for l in resolutions:
    for mode in ("whole", "band"):
        r, mb = load(f"meccano_{l}_{mode}")
        q = r["quality"]["after_smoothing"]["equilateral"]
        s = r["seconds"]["total"]
        hxt = hxt_seconds(r["tets"])
        print(f"| meccano l_r {float(l):.4g}, {mode} | {r['tets']:,} | {s:.2f} | {r['tets'] / s / 1e3:.0f} | {hxt:.2f} | "
              f"{hxt / s:.2f} | {q['min']:.3f} | {q['mean']:.3f} | {r['min_dihedral_deg']:.1f}° | "
              f"{r['max_dihedral_deg']:.1f}° | {mb:.0f} MB |")
for g, mb, h in gmsh:
    q = g["quality"]["equilateral"]
    s = g["seconds"]["total"]
    print(f"| Gmsh HXT H {h} | {g['tets']:,} | {s:.2f} | {g['tets'] / s / 1e3:.0f} | | | {q['min']:.3f} | "
          f"{q['mean']:.3f} | {g['quality']['min_dihedral_deg']:.1f}° | {g['quality']['max_dihedral_deg']:.1f}° | {mb:.0f} MB |")
EOF
