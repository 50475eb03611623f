#!/bin/sh
# Hostile input: every broken file (the committed corpus in tests/fixtures/bad and
# tests/fixtures/hostile, and ones made here: a million-node chain that ends in a cycle,
# lines of megabytes, a buffer named by a FIFO) gets exit code 3 or 4 and one line on
# stderr naming the file, within a time and memory bound, and leaves an existing output
# untouched.
# A few hostile-looking files are valid and must render.
# Usage: test_hostile.sh PTR SOURCE_DIR SANITIZED(0|1)
set -u
ptr=$1
src=$2
sanitized=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
passed=0
failed=0
worst=0
# Sanitizers reserve terabytes of address space and run several times slower.
if [ "$sanitized" = 1 ]; then limit=240; else limit=30; ulimit -v 4000000; fi

# run FILE EXPECTED: EXPECTED is "error" or "ok".
run() {
    file=$1
    echo "an existing image" >"$dir/out.exr"
    start=$(date +%s)
    # A first SIGTERM only asks ptr to finish its pass: KILL follows.
    timeout -k 5 "$limit" "$ptr" "$file" -o "$dir/out.exr" --samples 1 --width 8 --quiet 2>"$dir/err"
    code=$?
    took=$(($(date +%s) - start))
    [ $took -gt $worst ] && worst=$took
    lines=$(wc -l <"$dir/err")
    name=$(basename "$file")
    problem=
    if [ "$2" = ok ]; then
        [ $code -eq 0 ] || problem="exit $code, expected 0"
    elif [ $code -ne 3 ] && [ $code -ne 4 ]; then
        problem="exit $code (124, 137: time limit; 134, 139: a crash)"
    elif [ "$lines" -ne 1 ]; then
        problem="$lines lines on stderr"
    elif ! grep -q "^ptr: .*$name" "$dir/err"; then
        problem="the message does not name the file"
    elif [ "$(cat "$dir/out.exr")" != "an existing image" ]; then
        problem="the existing output was changed"
    fi
    if [ -n "$(ls -A "$dir" | grep ptr-)" ]; then
        problem="${problem:+$problem; }a temporary file was left"
    fi
    if [ -n "$problem" ]; then
        failed=$((failed + 1))
        echo "FAIL: $name: $problem: $(head -c 300 "$dir/err")" >&2
    else
        passed=$((passed + 1))
    fi
}

for file in "$src"/tests/fixtures/bad/*.gltf "$src"/tests/fixtures/bad/*.glb \
    "$src"/tests/fixtures/bad/*.obj "$src"/tests/fixtures/hostile/*.gltf \
    "$src"/tests/fixtures/hostile/*.glb "$src"/tests/fixtures/hostile/*.obj \
    "$src"/tests/fixtures/hostile/*.pdb "$src"/tests/fixtures/hostile/*.cif \
    "$src"/tests/fixtures/hostile/*.gz; do
    case $(basename "$file") in
    # Valid: re-centring on the camera makes a sphere 1e300 away renderable,
    # tinygltf reads the JSON of a GLB whose header says version 1, and ptr
    # reads Draco meshes by their bounds alone, never the stream they spoil;
    # an image it never reads may name anything; alternate locations in two
    # subchains of one chain are two atoms.
    translation_huge.gltf | glb_version_1.glb | draco_*.glb | image_uri_*.gltf | \
        structure_altloc_across_subchains_*.cif) run "$file" ok ;;
    *) run "$file" error ;;
    esac
done
run "$src/tests/fixtures" error                 # a folder
run "$dir/does-not-exist.gltf" error            # a missing file

# A buffer or an image named by a FIFO no one writes to: not waited on.
mkfifo "$dir/fifo"
sed 's|"uri": "\."|"uri": "fifo"|' "$src/tests/fixtures/hostile/buffer_uri_folder.gltf" \
    >"$dir/buffer_uri_fifo.gltf"
sed 's|"uri": "\."|"uri": "fifo"|' "$src/tests/fixtures/hostile/image_uri_folder.gltf" \
    >"$dir/image_uri_fifo.gltf"
run "$dir/buffer_uri_fifo.gltf" error
run "$dir/image_uri_fifo.gltf" ok

# A million nodes, each the child of the one before, the last one's child the first.
python3 - "$dir/million.gltf" <<'PY'
import sys
n = 1000000
with open(sys.argv[1], "w") as f:
    f.write('{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[')
    f.write(",".join('{"children":[%d]}' % ((i + 1) % n) for i in range(n)))
    f.write("]}")
PY
run "$dir/million.gltf" error
# Lines of megabytes: an object name of 5 MB, then a face line of 5 MB.
python3 - "$dir/long_lines.obj" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    f.write("o sphere" + "x" * 5000000 + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
    f.write("f" + " 1" * 2500000 + " 4\n")
PY
run "$dir/long_lines.obj" error

echo "slowest: ${worst} s (limit ${limit} s)"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
