#!/usr/bin/env python3
"""Checks that every #include of ptr's own code points to the same layer or to
one the layer may use (docs/architecture.md): the layers below it, never
above or beside it. Prints each offending line and exits 1; exits 0 when all
point down.

Usage: check_layers.py [SOURCE_DIR]
"""
import os
import re
import sys

# Each layer: its folder, and the layers its files may include.
LAYERS = {
    "base": ("src/base", []),
    "scene": ("src/scene", ["base"]),
    "sampling": ("src/sampling", ["base"]),
    "accel": ("src/accel", ["base", "scene"]),
    "render": ("src/render", ["base", "scene", "sampling", "accel"]),
    "importers": ("importers", ["base", "scene"]),
    "image": ("src/image", ["base"]),
    "color": ("src/color", ["base"]),
    "live": ("src/live", ["base"]),
    "app": ("src/app", ["base", "scene", "sampling", "accel", "render", "importers", "image",
                        "color", "live"]),
}
# Where a quoted include is looked for, after the including file's folder.
INCLUDE_DIRS = ["src", "importers", "importers/gltf"]
# Generated into the build tree from the file named.
GENERATED = {"base/version.h": "src/base/version.h.in"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(path):
    for name, (folder, _) in LAYERS.items():
        if path == folder or path.startswith(folder + "/"):
            return name
    return None


def resolve(root, including, name):
    if name in GENERATED:
        return GENERATED[name]
    for folder in [os.path.dirname(including)] + INCLUDE_DIRS:
        candidate = os.path.normpath(os.path.join(folder, name))
        if os.path.isfile(os.path.join(root, candidate)):
            return candidate
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems, checked = [], 0
    for name, (folder, allowed) in LAYERS.items():
        for directory, _, files in os.walk(os.path.join(root, folder)):
            for file in sorted(files):
                if not file.endswith((".c", ".h", ".cpp")):
                    continue
                path = os.path.relpath(os.path.join(directory, file), root)
                with open(os.path.join(root, path), encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        match = INCLUDE.match(line)
                        if not match:
                            continue
                        checked += 1
                        target = resolve(root, path, match.group(1))
                        to = layer_of(target) if target else None
                        if to is None:
                            problems.append(f"{path}:{number}: \"{match.group(1)}\" is not in any "
                                            "layer")
                        elif to != name and to not in allowed:
                            problems.append(f"{path}:{number}: {name} includes {to} "
                                            f"(\"{match.group(1)}\"); {name} may include "
                                            f"{', '.join(allowed) or 'nothing'} besides itself")
    for problem in problems:
        print(problem)
    print(f"{checked} includes checked, {len(problems)} pointing up or sideways")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
