"""What the checks of the importers' parallel conversion share: a cloud
written as one part (converted on all cores) and as two (each below the
threshold, converted one by one), valid and broken, read by ptr --dump-scene;
and the comparison of the two valid scenes."""
import json
import os
import subprocess
import sys
import tempfile


def dump_clouds(ptr, write_cloud, options=()):
    """ptr --dump-scene (with options) of write_cloud(path, parts, broken)
    for 1 and 2 parts, valid and broken: {(parts, broken): CompletedProcess}."""
    runs = {}
    with tempfile.TemporaryDirectory() as d:
        for broken in (False, True):
            for parts in (1, 2):
                path = os.path.join(d, f"cloud-{parts}-{broken}.glb")
                write_cloud(path, parts, broken)
                runs[parts, broken] = subprocess.run([ptr, "--dump-scene", *options, path],
                                                     capture_output=True, text=True, timeout=120)
    return runs


def spheres_differ(runs, count):
    """Why the valid clouds' scenes are not the same count spheres bit for
    bit, or None if they are."""
    whole, halves = runs[1, False], runs[2, False]
    if whole.returncode or halves.returncode:
        return f"valid files refused: {whole.stderr.strip()} / {halves.stderr.strip()}"
    a, b = json.loads(whole.stdout)["spheres"], json.loads(halves.stdout)["spheres"]
    if len(a) == count and a == b:
        return None
    differ = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), None)
    return f"{len(a)} and {len(b)} spheres; first difference at sphere {differ}"


def report(failures, checks):
    """Prints the failures and the tally; exits 1 if any check failed."""
    for f in failures:
        print(f)
    print(f"{checks - len(failures)} passed, {len(failures)} failed")
    sys.exit(1 if failures else 0)
