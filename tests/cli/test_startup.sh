#!/bin/sh
# The commands that write no image never load OpenImageIO (whose 260 shared
# libraries cost a quarter of a second and 128 MB before anything else), nor
# does a render to EXR (OpenEXR is linked); a render to PNG loads it once.
# Nothing but a render with --live or --tev loads the live module and
# libmicrohttpd. The dynamic loader's own log (LD_DEBUG=files) says which
# objects a process loaded, whatever the timings.
# Usage: test_startup.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"

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
    [ "$(loads ptr_live)" = 0 ] || fail "ptr $args loaded the live module"
    [ "$(loads libmicrohttpd)" = 0 ] || fail "ptr $args loaded libmicrohttpd"
done

# A render to EXR writes through OpenEXR alone; one to PNG loads the module once.
for ext in exr png; do
    LD_DEBUG=files "$ptr" "$src/scenes/seed.gltf" -o "$dir/a.$ext" --width 8 --height 8 \
        --samples 1 --quiet 2>"$dir/log" || fail "render to .$ext: exit code $?"
    [ -s "$dir/a.$ext" ] || fail "render to .$ext: no image"
    want=$([ $ext = exr ] && echo 0 || echo 1)
    [ "$(loads ptr_image_oiio)" = "$want" ] ||
        fail "render to .$ext: the image module was not loaded $want times"
    [ "$(loads libOpenImageIO.so)" = "$want" ] ||
        fail "render to .$ext: OpenImageIO was not loaded $want times"
    [ "$(loads libOpenEXR-)" = 1 ] || fail "render to .$ext: OpenEXR was not loaded once"
    # Without --live or --tev, no live view: neither its module nor the
    # libraries only it needs (libpng comes with OpenImageIO for .png).
    [ "$(loads ptr_live)" = 0 ] || fail "render to .$ext loaded the live module"
    [ "$(loads libmicrohttpd)" = 0 ] || fail "render to .$ext loaded libmicrohttpd"
done

# --live and --tev load the live module once, and with it libmicrohttpd.
for option in "--live 0" "--tev 1"; do
    # shellcheck disable=SC2086 # the option and its value are split on purpose
    LD_DEBUG=files "$ptr" "$src/scenes/seed.gltf" -o "$dir/b.exr" --width 8 --height 8 \
        --samples 1 --quiet $option 2>"$dir/log" || fail "render with $option: exit code $?"
    [ "$(loads ptr_live)" = 1 ] || fail "render with $option: the live module was not loaded once"
    [ "$(loads libmicrohttpd)" = 1 ] || fail "render with $option: libmicrohttpd was not loaded once"
done

finish "startup: passed"
