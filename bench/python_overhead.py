#!/usr/bin/env python3
"""What rendering from Python costs beside the command line: the CPU time
of ptr.load and Scene.render in this process against that of a whole `ptr`
run on the same file and options (import, tree, render and a small EXR),
each repeated, on one render thread. CPU time rather than wall time, so
that other work on the machine moves the figures less.

    scripts/make_cloud.py 1000000 cloud.glb
    PTR_LIBRARY=build/lib/libptr.so.1 PYTHONPATH=python \\
        /usr/bin/python3 bench/python_overhead.py build/src/ptr cloud.glb [REPEATS]

Prints each run's seconds and the ratio of the medians (Python / ptr)."""

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import ptr


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main():
    executable, scene_file = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 4
    context = ptr.Context(threads=1)
    cli, python = [], []
    with tempfile.TemporaryDirectory() as folder:
        output = os.path.join(folder, "image.exr")
        for _ in range(repeats):
            before = children_cpu()
            subprocess.run([executable, scene_file, "-o", output, "--width", "200", "--samples",
                            "8", "--threads", "1", "--quiet"], check=True)
            cli.append(children_cpu() - before)
            start = time.process_time()
            ptr.load(scene_file, context=context).render(200, samples=8)
            python.append(time.process_time() - start)
    print("ptr    CPU seconds:", " ".join("%.3f" % t for t in cli))
    print("Python CPU seconds:", " ".join("%.3f" % t for t in python))
    print("Python / ptr, medians: %.3f" % (statistics.median(python) / statistics.median(cli)))


if __name__ == "__main__":
    main()
