#!/usr/bin/env bash
# Sets up pcsg on a Debian 12 machine and runs it: installs the Debian packages that are
# missing (as root, or through sudo), configures and builds into build/, then
#
#   bash tools/setup.sh run    runs the main job on the default scene (see main_job below)
#   bash tools/setup.sh test   runs the whole test suite through ctest
#
# These are the two commands of README.md. Nothing is downloaded but Debian packages,
# and apt-get runs only when a package is missing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

mode=${1:-}
if [[ $mode != run && $mode != test ]]; then
    echo "usage: bash tools/setup.sh run|test" >&2
    exit 2
fi

PACKAGES=(build-essential cmake ninja-build pkg-config libfmt-dev libcli11-dev libpng-dev
          nlohmann-json3-dev libopenimageio-dev openimageio-tools libtbb-dev libgtest-dev
          libgmock-dev libbenchmark-dev libembree-dev povray graphviz clang clang-format lld chromium python3 ffmpeg
          openmpi-bin libopenmpi-dev)
BUILD=build              # the binaryDir of the "release" preset in CMakePresets.json
PCSG=$BUILD/tools/pcsg

# The main job on the default scene: ray trace its cyclic graph, anti-aliased like
# POV-Ray's +A0.3, and draw the graph itself.
main_job() {
    mkdir -p out
    "$PCSG" render scenes/sierpinski.pcsg -o out/sierpinski.png --adaptive 0.3
    "$PCSG" graph scenes/sierpinski.pcsg -o out/sierpinski.svg
    echo "setup: wrote out/sierpinski.png (the picture) and out/sierpinski.svg (its cyclic graph)"
}

install_missing() {
    local missing=() p
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q '^install ok installed$' ||
            missing+=("$p")
    done
    if ((${#missing[@]} == 0)); then
        echo "setup: all ${#PACKAGES[@]} Debian packages are installed"
        return
    fi
    local sudo=""
    if [[ $(id -u) != 0 ]]; then
        sudo=$(command -v sudo || true)
        if [[ -z $sudo ]]; then
            echo "setup: missing packages: ${missing[*]}" >&2
            echo "setup: run this as root, or install sudo, to install them" >&2
            exit 1
        fi
    fi
    echo "setup: installing ${missing[*]}"
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get update
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y "${missing[@]}"
}

install_missing
cmake --preset release
if [[ $mode == run ]]; then
    # Builds pcsg-image too: pcsg depends on the helper that writes EXR/TIFF and compares images.
    cmake --build "$BUILD" --target pcsg
    main_job
else
    cmake --build "$BUILD"
    ctest --test-dir "$BUILD" --output-on-failure -j2
fi
