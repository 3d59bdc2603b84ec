#!/usr/bin/env python3
"""Checks the library's layering (doc/design.md, "Layout and data flow"): a file of one folder of
module/include/meccano/ or module/src/ includes headers of its own folder and of the folders above it
in LAYERS only, plus error.hpp and surface/triangle_surface.hpp, which every layer may use. Prints each
upward include with its file and line and exits 1 if there is one."""
import pathlib
import re
import sys

LAYERS = ["geometry", "mesh", "surface", "io", "stages", "report", "inspect"]
SHARED = {"error.hpp", "surface/triangle_surface.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"](?:meccano/)?([a-z_]+/[a-z_]+\.hpp|[a-z_]+\.hpp)[>"]')

root = pathlib.Path(__file__).resolve().parent.parent / "module"
violations = []
for base in (root / "include" / "meccano", root / "src"):
    for path in sorted(base.rglob("*.[ch]pp")):
        folder = path.relative_to(base).parts[0]
        if folder not in LAYERS:
            if path.parent != base or path.name != "error.hpp":
                violations.append(f"{path}: not in a layer folder ({', '.join(LAYERS)})")
            continue
        allowed = set(LAYERS[: LAYERS.index(folder) + 1])
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            match = INCLUDE.match(line)
            if not match or match.group(1) in SHARED:
                continue
            included = match.group(1).split("/")[0] if "/" in match.group(1) else None
            if included is None or included not in allowed:
                violations.append(f"{path}:{number}: {folder}/ includes {match.group(1)}")
for violation in violations:
    print(violation)
print(f"layering: {len(violations)} violation(s)" if violations else "layering: ok")
sys.exit(1 if violations else 0)
