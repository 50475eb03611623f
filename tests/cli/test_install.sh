#!/bin/sh
# An installed tree renders on its own: `cmake --install` puts the image
# module where the installed ptr looks for it (PREFIX/lib/ptr), and without a
# working module a render to PNG fails with one line and exit code 10 while
# a render to EXR (OpenEXR, linked in) and the commands that write no image
# still work.
# Usage: test_install.sh CMAKE BUILD_DIR SOURCE_DIR
set -u
cmake=$1
build=$2
src=$3
. "$src/tests/support/shell_test.sh"

prefix=$dir/prefix
"$cmake" --install "$build" --prefix "$prefix" >/dev/null || { echo "FAIL: cmake --install" >&2; exit 1; }
ptr=$prefix/bin/ptr
module=$prefix/lib/ptr/ptr_image_oiio.so
[ -x "$ptr" ] && [ -f "$module" ] || { echo "FAIL: bin/ptr or lib/ptr/ptr_image_oiio.so not installed" >&2; exit 1; }

render() { "$ptr" "$src/scenes/seed.gltf" -o "$1" --width 8 --height 8 --samples 1 --quiet; }

LD_DEBUG=files render "$dir/a.png" 2>"$dir/log" || fail "installed render: exit code $?"
[ -s "$dir/a.png" ] || fail "installed render: no image"
grep -q "file=$module .*dynamically loaded" "$dir/log" || fail "the installed module was not the one loaded"

# expect_broken WHAT: a render and a merge fail with exit 10 and one line
# naming the module, writing nothing; EXR, --version and --dump-scene still work.
expect_broken() {
    render "$dir/b.png" 2>"$dir/err"
    code=$?
    [ $code = 10 ] || fail "$1: render exit code $code, not 10"
    [ "$(wc -l <"$dir/err")" = 1 ] && grep -q "^ptr: $module: " "$dir/err" ||
        fail "$1: render did not say one line about the module: $(cat "$dir/err")"
    [ -e "$dir/b.png" ] && fail "$1: render wrote an image"
    "$ptr" merge "$dir/a.png" -o "$dir/c.exr" --quiet 2>"$dir/err"
    code=$?
    [ $code = 10 ] || fail "$1: merge exit code $code, not 10"
    render "$dir/d.exr" || fail "$1: a render to EXR failed"
    "$ptr" --version >/dev/null || fail "$1: --version failed"
    "$ptr" --dump-scene "$src/scenes/seed.gltf" >/dev/null || fail "$1: --dump-scene failed"
}

mv "$module" "$dir/module.so"
expect_broken "module missing"
echo "not a shared object" >"$module"
expect_broken "module broken"

finish "install: passed"
