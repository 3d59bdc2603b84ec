#!/usr/bin/env bash
# Real faults and hard surfaces (issue 17): meccano-immerse on the shared SCEC faults and on the synthetic
# hard surfaces of tests/data/hard_surfaces, each in a box around it at four resolutions, against Gmsh
# HXT on the same box, as a Markdown section (doc/benchmarks.md, "Real faults and hard surfaces").
#
# Cases: the GOCAD TSurf faults of ../shared/data/faults (read as .ts; skipped with a message if the
# folder is missing) and the OBJ files of tests/data/hard_surfaces (meshes/generate_surfaces.py --hard).
# Box: the surface's bounding box enlarged by 10 % of E on every side, E its largest extent; l_r = E/30,
# E/50, E/70, E/100. For each case and l_r:
#   - the module (all four steps) under /usr/bin/time -v, then `meccano-immerse measure` against the
#     surface file; a failed run is recorded as FAILED with the last line it wrote, and the rest goes on;
#   - Gmsh HXT (reference-gmsh) at equal tet count: uniform sizes H, one after the other, until their
#     tet counts bracket the module's (2-4 runs), each on the surface split into 4 at edge midpoints until
#     its mean edge is at most H (Gmsh keeps S's triangles: 1 km ones would set the size near S, and
#     below 0.7 x their edge it leaves flat tets against them);
#   - Gmsh HXT at equal interface resolution: the surface split until its mean edge is at most sqrt(2)
#     h_S, h_S the mean edge of the module's interface faces, and the size field --size-near-surface h_S
#     --size-distance 4 l_r --size F, F = 0.3 x the meccano cell edge of the box (bench_faults.py
#     far_size says why).
# tests/bench/bench_faults.py chooses the boxes, sizes and surfaces and renders the tables and the
# issue's targets. Meshes are deleted once measured; the reports stay in the work folder.
#
# Usage: tests/bench/bench_faults.sh [--quick] [--module-only] [--build DIR] [--threads N] [--work DIR]
#                                    [--cases A,B,...] [--divisors D,...] [--write]
#   --quick      E/30 and E/50 on three cases (shell_beds, creased, vertical), a smoke run of a few minutes
#   --module-only  no Gmsh runs: the module's tables and the issue's targets 1-4 in 15-25 minutes (target 5
#                and the HXT columns then read NOT MEASURED / no HXT run)
#   --build DIR  the build directory with module/meccano-immerse and reference/reference-gmsh (default: build)
#   --threads N  threads for meccano-immerse and Gmsh (default: all cores)
#   --work DIR   keep the runs' reports and the split surfaces in DIR (default: a temporary directory,
#                removed at the end); `bench_faults.py report DIR [doc/benchmarks.md]` re-renders them
#   --cases LIST only these cases (names as bench_faults.py cases prints them: shell_beds, creased, ...)
#   --divisors LIST  only these resolutions l_r = E / D (for example 30,50; targets 1 and 3 then read
#                NOT MEASURED where they need all four)
#   --write      also write the section into doc/benchmarks.md (between its bench_faults markers)
# Each run is stopped after 30 minutes (recorded as FAILED). The quick run takes about 8 minutes on 2 busy
# cores, the full run 3-4 hours (mostly the graded HXT runs on the finely split surfaces).
set -euo pipefail
cd "$(dirname "$0")/../.."

quick=0
module_only=0
build=build
threads=$(nproc)
work=""
cases=""
divisors=""
write=0
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --module-only) module_only=1; shift ;;
    --build) build=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --cases) cases=$2; shift 2 ;;
    --divisors) divisors=$2; shift 2 ;;
    --write) write=1; shift ;;
    *) echo "bench_faults: unknown argument $1 (see the header of $0)" >&2; exit 2 ;;
  esac
done

cli=$build/module/meccano-immerse
gmsh_tool=$build/reference/reference-gmsh
for tool in "$cli" "$gmsh_tool"; do
  [ -x "$tool" ] || { echo "bench_faults: $tool is missing: build it first" >&2; exit 1; }
done
python=/usr/bin/python3  # Debian's, with numpy and matplotlib (scripts/setup.sh)
helper=tests/bench/bench_faults.py
faults_dir=../shared/data/faults
hard_dir=tests/data/hard_surfaces
run_timeout=1800

mode=full
if [ $quick = 1 ]; then
  mode=quick
  if [ -z "$cases" ]; then
    if [ -d "$faults_dir" ]; then cases=shell_beds,creased,vertical; else cases=creased,vertical,thin_long; fi
  fi
fi

if [ -z "$work" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work/surfaces"
[ -z "$divisors" ] || mode=$divisors
echo "$mode run$([ $module_only = 0 ] || echo ', module only'), $threads threads, build $build" > "$work/options"
: > "$work/manifest.tsv"

# last_message STDERR CODE: the last line a tool wrote on STDERR, but for the pointer to its --help, or its
# exit status CODE if it wrote nothing.
last_message() {
  { grep -v '^(see .* --help)$' "$1" | tail -n 1; echo "exit status $2"; } | head -n 1
}

# run ID CASE KIND DIVISOR FAMILY PARAMETER LABEL COMMAND...: runs COMMAND (a meshing tool, given --quiet,
# --output ID.msh and --report ID.json here) under /usr/bin/time and a time limit, and records it in the
# manifest: ok, or FAILED with its last message in ID.error. Returns 1 if it failed.
run() {
  local id=$1 case=$2 kind=$3 divisor=$4 family=$5 parameter=$6 label=$7 state=ok code
  shift 7
  if timeout "$run_timeout" /usr/bin/time -v -o "$work/$id.time" "$@" --quiet --output "$work/$id.msh" \
       --report "$work/$id.json" 2> "$work/$id.stderr"; then
    sed -n 's/.*Maximum resident set size (kbytes): //p' "$work/$id.time" > "$work/$id.rss"
  else
    code=$?
    state=FAILED
    if [ $code = 124 ]; then
      echo "stopped after $run_timeout s" > "$work/$id.error"
    else
      last_message "$work/$id.stderr" "$code" > "$work/$id.error"
    fi
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$id" "$case" "$kind" "$divisor" "$family" "$parameter" "$label" "$state" \
    >> "$work/manifest.tsv"
  echo "$(date +%T) $id: $label: $state" >&2
  [ $state = ok ]
}

# run_hxt ID CASE KIND DIVISOR FAMILY PARAMETER LABEL OPTIONS...: Gmsh HXT (reference-gmsh --algorithm hxt
# OPTIONS) as `run` runs it, on `threads` threads. Gmsh 4.8.4's HXT cracks some meshes around S on several
# threads (two nodes at one point, reference-gmsh refuses the mesh); that run stays FAILED in the manifest
# and HXT runs again on one thread as ID_1thread, which the report marks. Sets `last_id` to the run kept.
run_hxt() {
  local id=$1 label=$7
  last_id=$id
  run "${@:1:7}" "$gmsh_tool" --algorithm hxt --threads "$threads" "${@:8}" && return
  [ "$threads" -gt 1 ] && grep -q "share their point with another node" "$work/$id.error" || return 1
  last_id=${id}_1thread
  run "$last_id" "${@:2:5}" "$label, 1 thread" "$gmsh_tool" --algorithm hxt --threads 1 "${@:8}"
}

# measure ID FILE NAME: measures ID.msh against the surface FILE: ID.measure.json, or ID.measure.error with
# its last message.
measure() {
  local code
  timeout "$run_timeout" "$cli" measure "$work/$1.msh" --surface "$2:$3" --quiet --report "$work/$1.measure.json" \
    2> "$work/$1.measure.stderr" && return
  code=$?
  last_message "$work/$1.measure.stderr" "$code" > "$work/$1.measure.error"
}

# split FILE EDGE: the surface FILE split until its mean edge is at most EDGE; sets `split_surface` and
# `split_label`.
split() {
  local output levels triangles
  output=$("$python" "$helper" subdivide "$1" "$2" "$work/surfaces")
  read -r split_surface levels triangles _ <<< "$output"
  split_label="S split $levels× ($triangles triangles)"
}

case_list=$("$python" "$helper" cases "$faults_dir" "$hard_dir" "$cases")
while read -r name kind file <&3; do
  plan=$("$python" "$helper" plan "$file" $mode)
  read -r box extent <<< "$plan"
  echo "$(date +%T) $name: box $box, E $extent" >&2
  while read -r divisor l <&4; do
    base=${name}_E$divisor
    run "$base" "$name" "$kind" "$divisor" meccano "$l" "l_r $l" "$cli" --box "$box" --threads "$threads" \
      --surface "$file:$name" --resolution "$l" || continue
    measure "$base" "$file" "$name"
    rm "$work/$base.msh"
    [ $module_only = 0 ] || continue

    # HXT at equal tet count: sizes until the tet counts bracket the module's.
    reports=()
    while h=$("$python" "$helper" hxt-size "$work/$base.json" "$box" "${reports[@]}") && [ -n "$h" ]; do
      split "$file" "$h"
      id=${base}_hxt_$h
      run_hxt "$id" "$name" "$kind" "$divisor" hxt "$h" "H $h, $split_label" --box "$box" \
        --surface "$split_surface:$name" --size "$h" || break
      id=$last_id
      rm "$work/$id.msh"
      reports+=("$work/$id.json")
    done

    # HXT at equal interface resolution: graded from h_S at S to the far size over 4 l_r.
    [ -f "$work/$base.measure.json" ] || continue
    h_s=$("$python" tests/bench/compare_references.py interface-edge "$work/$base.measure.json")
    far=$("$python" "$helper" far-size "$box")
    split "$file" "$("$python" -c "print(f'{2 ** 0.5 * $h_s:.6g}')")"
    id=${base}_hxt-field
    run_hxt "$id" "$name" "$kind" "$divisor" hxt-field "$h_s" "h_S $h_s, $split_label, F $far" --box "$box" \
      --surface "$split_surface:$name" --size "$far" --size-near-surface "$h_s" \
      --size-distance "$("$python" -c "print(f'{4 * $l:.6g}')")" && rm "$work/$last_id.msh"
  done 4< <(tail -n +2 <<< "$plan")
done 3<<< "$case_list"

echo "$(date -u '+%Y-%m-%d %H:%M') $(cut -d ' ' -f 1-3 /proc/loadavg)" > "$work/finished"
if [ $write = 1 ]; then
  "$python" "$helper" report "$work" doc/benchmarks.md
  echo "bench_faults: wrote the bench_faults section of doc/benchmarks.md" >&2
else
  "$python" "$helper" report "$work"
fi
