#!/usr/bin/env python3
"""Checks that every #include of ptr's own code points to the same layer or to
one the layer may use (docs/architecture.md): the layers below it, never
above or beside it; and that no units include each other, in a ring of two
or more. A unit is foo.c or foo.cpp with its foo.h; it includes bar when one
of its files includes bar.h, directly or through headers that are no unit's
(an interface a few units share, such as importer_internal.h). Prints each
offending line and each cycle of units with the includes that close it, and
exits 1; exits 0 when all point down and no unit depends on itself.

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
    "denoise": ("src/denoise", ["base"]),
    # The public header of the library (include/ptr/ptr.h): self-contained.
    "public": ("include", []),
    "api": ("src/api", ["base", "scene", "sampling", "accel", "render", "importers", "image",
                        "color", "denoise", "public"]),
    "app": ("src/app", ["base", "scene", "sampling", "accel", "render", "importers", "image",
                        "color", "live", "denoise", "public", "api"]),
}
# Where a quoted include is looked for, after the including file's folder.
INCLUDE_DIRS = ["src", "include", "importers", "importers/gltf"]
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


def unit_of(path):
    """foo for foo.c, foo.cpp, foo.h (and foo.h.in, a generated foo.h)."""
    if path.endswith(".in"):
        path = path[:-len(".in")]
    return os.path.splitext(path)[0]


def unit_includes(file_includes):
    """unit -> {unit it includes: the includes that do, "file:line" each},
    through headers of no unit and other included files (cli_options.def),
    from file -> [(line, included file)], every file a key."""
    units = {unit_of(path) for path in file_includes if path.endswith((".c", ".cpp"))}

    def header_of_unit(path):
        return path.endswith((".h", ".h.in")) and unit_of(path) in units

    includes = {}
    for path in sorted(file_includes):
        unit = unit_of(path)
        if unit not in units:
            continue
        # Depth first through the headers of no unit, each once.
        stack, seen = [(path, [])], {path}
        while stack:
            current, chain = stack.pop()
            for number, target in file_includes.get(current, []):
                step = chain + [f"{current}:{number}"]
                if header_of_unit(target):
                    if unit_of(target) != unit:
                        includes.setdefault(unit, {}).setdefault(unit_of(target), step)
                elif target not in seen:
                    seen.add(target)
                    stack.append((target, step))
    return includes


def unit_cycles(includes):
    """Every elementary cycle of the graph of unit_includes, each once,
    starting from its least unit."""
    cycles = []

    def extend(path, on_path):
        for nxt in sorted(includes.get(path[-1], {})):
            if nxt == path[0]:
                cycles.append(list(path))
            elif nxt > path[0] and nxt not in on_path:
                on_path.add(nxt)
                extend(path + [nxt], on_path)
                on_path.discard(nxt)

    for start in sorted(includes):
        extend([start], {start})
    return cycles


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems, checked = [], 0
    file_includes = {}  # file -> [(line, included file)]
    for name, (folder, allowed) in LAYERS.items():
        for directory, _, files in os.walk(os.path.join(root, folder)):
            for file in sorted(files):
                if not file.endswith((".c", ".h", ".cpp")):
                    continue
                path = os.path.relpath(os.path.join(directory, file), root)
                file_includes.setdefault(path, [])
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
                        if target:
                            file_includes[path].append((number, target))
    includes = unit_includes(file_includes)
    cycles = unit_cycles(includes)
    for problem in problems:
        print(problem)
    for cycle in cycles:
        ring = cycle + cycle[:1]
        print("unit cycle: " + " -> ".join(ring))
        for a, b in zip(ring, ring[1:]):
            print(f"  {a} includes {b}: {', then '.join(includes[a][b])}")
    print(f"{checked} includes checked, {len(problems)} pointing up or sideways, "
          f"{len(cycles)} cycles of units")
    return 1 if problems or cycles else 0


if __name__ == "__main__":
    sys.exit(main())
