#!/bin/sh
# Out of memory, wherever it strikes: a scene of 10^6 spheres rendered to EXR
# under a ladder of address-space limits (ulimit -v), so that memory runs out
# in turn while the image module and its libraries load, while the scene is
# imported, while the tree is built and while the image is written. Every run
# must end in exit 0 with a complete image, or exit 6 with one line on stderr
# saying "out of memory" and the existing output left as it was; never 4, 10,
# a signal or a half-written file. The ladder must see both ends.
# Usage: test_memory_limits.sh PTR SOURCE_DIR SANITIZED(0|1)
set -u
ptr=$1
src=$2
# Sanitizers reserve terabytes of address space: a limit means nothing there.
if [ "$3" = 1 ]; then
    echo "skipped: address-space limits do not apply under the sanitizers"
    exit 77
fi
. "$src/tests/support/shell_test.sh"

python3 - "$src/scripts" "$dir/million.glb" <<'PY'
import random, sys
sys.path.insert(0, sys.argv[1])
import make_scenes
rng = random.Random(1)
spheres = [dict(material="lambertian", radius=0.02, albedo=[0.8, 0.8, 0.8],
                center=[rng.uniform(-10, 10), rng.uniform(0, 6), rng.uniform(-10, 10)])
           for _ in range(1000000)]
scene = {"name": "million", "spheres": spheres, "sky": {"type": "gradient"}}
make_scenes.write(*make_scenes.build(scene, instanced=True), sys.argv[2])
PY

rendered=0
refused=0
for mb in 100 200 300 400 450 500 550 600 650 700 800 1000; do
    echo "an existing image" >"$dir/out.exr"
    (ulimit -v $((mb * 1024)) && exec timeout 300 "$ptr" "$dir/million.glb" -o "$dir/out.exr" \
        --samples 1 --width 64 --quiet) 2>"$dir/err"
    code=$?
    echo "$mb MB: exit $code $(head -c 200 "$dir/err")"
    case $code in
    0)
        rendered=$((rendered + 1))
        iinfo -v "$dir/out.exr" 2>/dev/null | grep -q 'ptr:samples: 1' ||
            fail "$mb MB: exit 0 without a complete image"
        ;;
    6)
        refused=$((refused + 1))
        [ "$(cat "$dir/out.exr")" = "an existing image" ] ||
            fail "$mb MB: exit 6, but the existing output was changed"
        [ "$(wc -l <"$dir/err")" -eq 1 ] && grep -q '^ptr: .*out of memory' "$dir/err" ||
            fail "$mb MB: exit 6 without one line saying out of memory"
        ;;
    *) fail "$mb MB: exit $code (only 0 or 6 may end a run out of memory)" ;;
    esac
    ls -A "$dir" | grep -q 'ptr-' && fail "$mb MB: a temporary file was left"
    rm -f "$dir"/.*ptr-*
done
[ $rendered -gt 0 ] || fail "no limit of the ladder let the scene render"
[ $refused -gt 0 ] || fail "no limit of the ladder ran out of memory"
finish "$rendered limits rendered, $refused ran out of memory"
