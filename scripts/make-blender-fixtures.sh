#!/bin/sh
# Regenerates tests/fixtures/blender/ with Debian's Blender (installed if
# missing). Not part of the test run: its output is committed.
set -eu
cd "$(dirname "$0")/.."
if ! command -v blender >/dev/null || ! dpkg -s python3-numpy >/dev/null 2>&1; then
    run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
    run apt-get update -qq
    DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq blender python3-numpy >/dev/null
fi
blender --version | head -1
blender -b --factory-startup --python-exit-code 1 --python scripts/blender_fixtures.py -- \
    "$PWD/tests/fixtures/blender"
ls -l tests/fixtures/blender
