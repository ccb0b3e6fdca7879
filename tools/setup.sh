#!/usr/bin/env bash
# Installs the Debian 12 packages octray needs to build, test and benchmark. Idempotent:
# it asks dpkg first and only runs apt-get when something is missing, so it is cheap to
# call before every build. Uses sudo only when not already root. clang and its runtime
# build the asan preset (ASan, UBSan, libFuzzer); dpkg-dev and xz-utils let
# tests/tsan/build_tbb.sh fetch and unpack oneTBB's Debian source. slurmctld, slurmd,
# slurm-client and munge let tests/farm/slurm.sh run a single-node Slurm (it starts the
# daemons itself, from a temporary folder; installing them starts nothing here).
# python3-matplotlib draws bench/plot.py's charts; groff-base checks the man pages.
# libisal-dev (ISA-L's igzip) compresses the ZIP chunks of the EXRs octray writes;
# zlib1g-dev (which libpng-dev brings too) checks and joins their checksums.
# libcpp-httplib-dev is the HTTP server of `octray view` (it brings libssl-dev, whose
# headers its own include; libjpeg62-turbo-dev is its picture stream's JPEG); chromium, chromium-driver and python3-selenium drive its page headless
# in tests/view/browser_test.py.
set -euo pipefail

packages=(
    cmake ninja-build g++ pkg-config
    clang libclang-rt-14-dev clang-format
    dpkg-dev xz-utils
    libxsimd-dev libopenexr-dev libimath-dev openexr libtbb-dev
    libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libsimdjson-dev
    libpng-dev zlib1g-dev libisal-dev libembree-dev
    slurmctld slurmd slurm-client munge
    python3-matplotlib groff-base
    libcpp-httplib-dev libjpeg62-turbo-dev chromium chromium-driver python3-selenium
)

missing=()
for package in "${packages[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
    if [[ "$status" != "install ok installed" ]]; then
        missing+=("$package")
    fi
done

if ((${#missing[@]} == 0)); then
    echo "setup: all ${#packages[@]} packages are installed"
    exit 0
fi

as_root=()
if [[ "$(id -u)" -ne 0 ]]; then
    if ! command -v sudo >/dev/null 2>&1; then
        echo "setup: missing packages (${missing[*]}) and not root; install them as root" >&2
        exit 1
    fi
    as_root=(sudo)
fi

echo "setup: installing ${missing[*]}"
# Non-interactive: CI has no stdin, and no package here needs a question answered.
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y --no-install-recommends "${missing[@]}"
