#!/usr/bin/env bash
# Two builds of meccano-immerse side by side on the shared faults and the hard surfaces of
# tests/data/hard_surfaces (doc/benchmarks.md, "Crease mends", "Western Santa Cruz Island without
# retries"): for each resolution and surface, BEFORE then AFTER, in the box and at the l_r of
# bench_faults.sh (the surface's bounding box grown by E/10, l_r = E / DIVISOR), each mesh checked
# (`check`) and measured against the surface file (`measure`). Prints one Markdown row per run: tets,
# estimate / tets, retries (finer ones, and "side" for the other side), seconds, improvement seconds,
# eta min (meccano / equilateral), dihedral range, normal deviation (area-weighted mean / max),
# Hausdorff, and the crease mends (moves / splits) with the S_M edge flips (all kinds).
#
# usage: tests/bench/compare_builds_on_faults.sh BEFORE_BINARY AFTER_BINARY WORKDIR ["30 50 70 100"]
# Single runs, one after the other: compare the two rows of a case, and read seconds loosely.
set -euo pipefail
before=$1 after=$2 work=$3 divisors=${4:-"30 50 70 100"}
python=/usr/bin/python3  # Debian's (scripts/setup.sh), as bench_faults.sh uses
here=$(cd "$(dirname "$0")" && pwd)
faults=$here/../../../shared/data/faults
hard=$here/../data/hard_surfaces
mkdir -p "$work"
for divisor in $divisors; do
  for fault in "$faults"/*.ts "$hard"/*.obj; do
    read -r box extent < <($python -c "
import sys; sys.path.insert(0, '$here')
from bench_faults import case_box, read_surface
b, e = case_box(read_surface('$fault')[0]); print(','.join(repr(c) for c in b), e)")
    name=$(basename "$fault" | sed 's/\.[a-z]*$//' | awk -F- '{print (NF > 1 ? $4 : $0)}')
    resolution=$($python -c "print($extent / $divisor)")
    for which in before after; do
      binary=$before; [ "$which" = after ] && binary=$after
      if "$binary" --box "$box" --surface "$fault:fault" --resolution "$resolution" --quiet \
          --output "$work/mesh.msh" --report "$work/run.json" 2>"$work/error"; then
        "$binary" check "$work/mesh.msh" --quiet >/dev/null || echo "CHECK FAILED $name E/$divisor $which"
        "$binary" measure "$work/mesh.msh" --surface "$fault:fault" --quiet --report "$work/measure.json"
        $python -c "
import json
r = json.load(open('$work/run.json')); m = json.load(open('$work/measure.json'))
i = m['interfaces'][0]; q = r['quality']['after_smoothing']; o = r['improvement']['operations']
finer = len(r.get('finer_retries', []))
retries = ' '.join([f'{finer} finer'] * (finer > 0) + ['side'] * ('side_retry' in r)) or '–'
print(f\"| $name | E/$divisor | $which | {r['tets']:,} | {r['estimated_tets'] / r['tets']:.2f} | {retries} \"
      f\"| {r['seconds']['total']:.2f} | {r['seconds']['improvement']:.2f} \"
      f\"| {q['meccano']['min']:.3f} / {q['equilateral']['min']:.3f} | {r['min_dihedral_deg']:.1f}–{r['max_dihedral_deg']:.1f}° \"
      f\"| {i['normal_deviation_deg']['mean']:.2f} / {i['normal_deviation_deg']['max']:.1f}° | {i['hausdorff']:.3g} \"
      f\"| {o.get('crease_moves', '–')} / {o.get('crease_splits', '–')} / {o['surface_edge_flips']} |\")"
      else
        echo "| $name | E/$divisor | $which | FAILED: $(tail -c 200 "$work/error") |"
      fi
    done
  done
done
