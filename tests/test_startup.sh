#!/bin/sh
# The commands that write no image never load OpenImageIO (whose 260 shared
# libraries cost a quarter of a second and 128 MB before anything else); a
# render does, once. The dynamic loader's own log (LD_DEBUG=files) says which
# objects a process loaded, whatever the timings.
# Usage: test_startup.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/shell_test.sh"

# loads NAME: how many times the log names NAME as loaded.
loads() { grep -c "file=[^ ]*$1.* generating link map" "$dir/log"; }

for args in "--version" "--help" "--dump-scene $src/scenes/seed.gltf" "--print-dispatch" \
            "--list-views"; do
    # shellcheck disable=SC2086 # the arguments are split on purpose
    LD_DEBUG=files "$ptr" $args >/dev/null 2>"$dir/log" || fail "ptr $args: exit code $?"
    # The log works: it shows the libraries ptr links.
    [ "$(loads libOpenColorIO)" = 1 ] || fail "ptr $args: LD_DEBUG=files did not log the libraries"
    [ "$(loads libOpenImageIO)" = 0 ] || fail "ptr $args loaded OpenImageIO"
    [ "$(loads ptr_image_oiio)" = 0 ] || fail "ptr $args loaded the image module"
done

LD_DEBUG=files "$ptr" "$src/scenes/seed.gltf" -o "$dir/a.exr" --width 8 --height 8 --samples 1 \
    --quiet 2>"$dir/log" || fail "render: exit code $?"
[ -s "$dir/a.exr" ] || fail "render: no image"
[ "$(loads ptr_image_oiio)" = 1 ] || fail "render: the image module was not loaded once"
[ "$(loads libOpenImageIO.so)" = 1 ] || fail "render: OpenImageIO was not loaded once"

finish "startup: passed"
