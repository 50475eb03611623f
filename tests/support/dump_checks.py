"""What the checks of ptr's imports through --dump-scene share: failures
collected rather than stopping at the first, and a scene's spheres as ptr
dumps them."""
import json
import subprocess
import sys


class Checks:
    def __init__(self, name, ptr):
        self.name, self.ptr = name, ptr
        self.failures, self.count = [], 0

    def expect(self, what, ok):
        self.count += 1
        if not ok:
            self.failures.append(what)

    def dump(self, path, *options):
        """The spheres of ptr --dump-scene path options, a failure if it fails."""
        run = subprocess.run([self.ptr, "--dump-scene", path, *options], capture_output=True,
                             text=True)
        self.expect(f"{path} {options}: exit {run.returncode}: {run.stderr}",
                    run.returncode == 0)
        return json.loads(run.stdout)["spheres"] if run.returncode == 0 else []

    def finish(self):
        """Prints the count and the first failures; exits 1 if any."""
        print(f"{self.name}: {self.count} checks, {len(self.failures)} failed")
        for f in self.failures[:30]:
            print("FAIL:", f)
        sys.exit(1 if self.failures else 0)
