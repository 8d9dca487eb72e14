# Shared by scripts/demo, scripts/test and scripts/fuzz: install what is missing, configure, build.
# shellcheck shell=bash

SV_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# What a minimal Debian 12 (debootstrap --variant=minbase) lacks for scripts/demo and scripts/test;
# scripts/fresh-check proves the list there. The reference renderer links libOpenGL and libEGL
# (libopengl-dev, libegl-dev; libgl-dev for the headers) and runs on llvmpipe (libegl-mesa0,
# libgl1-mesa-dri); python3 is for scripts/quality and scripts/bench-masking; clang and its runtime
# (libclang-rt-14-dev) build the libFuzzer targets (scripts/fuzz builds and runs them);
# libgdal-dev is the terrain loaders' reader of DEM rasters (GeoTIFF, SRTM .hgt, …); openscenegraph's
# osgconv is the OpenFlight tests' independent peer (it writes and reads .flt); libopenvdb-dev is the
# volume loader's reader of OpenVDB files (and the tests' writer of them); python3-vtk9 is VTK's CPU
# volume ray caster, the volumes' baseline (bench/vtk_volume.py, under xvfb-run); libminizip-dev and
# libtinyxml2-dev are the display stage's zip and XML readers of MPCDI files (docs/display.md);
# libopenmpi-dev and openmpi-bin (mpirun) run an IG over several processes (docs/cluster.md);
# universal-ctags measures the functions for the short-functions rule (scripts/long-functions).
SV_PACKAGES=(cmake g++ ninja-build pkg-config libgtest-dev libgmock-dev libbenchmark-dev
  libhwy-dev libtinygltf-dev libtinyobjloader-dev libstb-dev libpng-dev zlib1g-dev libturbojpeg0-dev libdraco-dev libassimp-dev nlohmann-json3-dev
  libcli11-dev libfmt-dev libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri python3
  clang libclang-rt-14-dev libgdal-dev libsdl2-dev xvfb xauth x11-apps tshark openscenegraph libmeshoptimizer-dev
  libopenvdb-dev python3-vtk9 libminizip-dev libtinyxml2-dev libopenmpi-dev openmpi-bin
  universal-ctags)

sv_install_packages() {
  local missing=()
  for p in "${SV_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "synthvis: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# sv_data: the real data the tests and demos read, unpacked (never committed) from Debian packages
# — with `dpkg -x`, not installed, so without their runtimes: r-cran-stars (tif/olinda_dem_utm25s.tif,
# a 111×111 float32 DEM in UTM 25S, and tif/L7_ETMs.tif, Landsat bands of the same ground),
# r-cran-terra (ex/elev.tif, 95×90 int16 heights in longitude/latitude with no-data cells) and
# xplanet (stars/BSC, the Yale Bright Star Catalogue: the light points' star field) and
# mricron-data (templates/ch2.nii.gz, the Colin 27 T1 MRI head: the volumes' real data). The .debs are
# cached in build-data/debs and unpacked into build-data/root; the tests find the DEMs under
# build-data/root/usr/lib/R/site-library (SV_TERRAIN_DATA_DIR) and the stars under
# build-data/root/usr/share/xplanet (SV_STAR_CATALOG) and the head under
# build-data/root/usr/share/mricron/templates (SV_VOLUME_DATA_DIR).
SV_DATA_DEBS=(r-cran-stars r-cran-terra xplanet mricron-data)

sv_data() {
  local debs="$SV_ROOT/build-data/debs" root="$SV_ROOT/build-data/root"
  local lib="$root/usr/lib/R/site-library"
  if [ -f "$lib/stars/tif/olinda_dem_utm25s.tif" ] && [ -f "$lib/terra/ex/elev.tif" ] &&
    [ -f "$root/usr/share/xplanet/stars/BSC" ] && [ -f "$root/usr/share/mricron/templates/ch2.nii.gz" ]; then
    return 0
  fi
  mkdir -p "$debs" "$root"
  local missing=() p
  for p in "${SV_DATA_DEBS[@]}"; do
    compgen -G "$debs/${p}_*.deb" >/dev/null || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "synthvis: downloading ${missing[*]} (test and demo data) into $debs"
    # As root, apt drops privileges to _apt for downloads, which cannot write to most directories:
    # download as root instead (nothing is installed, the files are only unpacked).
    local apt=(apt-get download -qq -o APT::Sandbox::User=root)
    if ! (cd "$debs" && "${apt[@]}" "${missing[@]}"); then
      # A fresh system has no package lists yet.
      local sudo=""
      [ "$(id -u)" -ne 0 ] && sudo="sudo"
      $sudo apt-get update -qq
      (cd "$debs" && "${apt[@]}" "${missing[@]}")
    fi
  fi
  for p in "${SV_DATA_DEBS[@]}"; do
    local f
    for f in "$debs/${p}"_*.deb; do dpkg -x "$f" "$root"; done
  done
  echo "synthvis: test and demo data in $root"
}

# sv_build DIR [cmake args...]: configure (once) and build everything in DIR.
# sv_build DIR CMAKE_ARGS...: configure DIR and build it all, or only SV_BUILD_TARGET if set.
sv_build() {
  local dir="$1"
  shift
  cmake -S "$SV_ROOT" -B "$dir" -G Ninja "$@" >/dev/null
  cmake --build "$dir" --parallel "$(nproc)" --target "${SV_BUILD_TARGET:-all}"
}

# The libFuzzer build (fuzz/README.md): clang, every synthvis library instrumented, no tests or
# benchmarks. SV_FUZZ_DIR is its build directory; sv_fuzz_targets prints the targets' names
# (json_scene, gltf, ...), one per fuzz/fuzz_<name>.cpp.
SV_FUZZ_DIR="$SV_ROOT/build-fuzz"

sv_fuzz_targets() {
  local f
  for f in "$SV_ROOT"/fuzz/fuzz_*.cpp; do
    f="${f##*/fuzz_}"
    echo "${f%.cpp}"
  done
}

# sv_build_fuzz: configure (once) SV_FUZZ_DIR and build the fuzz_<name> executables only.
sv_build_fuzz() {
  local targets=()
  mapfile -t targets < <(sv_fuzz_targets)
  cmake -S "$SV_ROOT" -B "$SV_FUZZ_DIR" -G Ninja -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSV_BUILD_FUZZ=ON -DSV_BUILD_TESTS=OFF -DSV_BUILD_BENCH=OFF >/dev/null
  cmake --build "$SV_FUZZ_DIR" --parallel "$(nproc)" --target "${targets[@]/#/fuzz_}"
}

# sv_assimp_models: Debian's assimp-testmodels, downloaded with apt-get download and unpacked into
# build-data/ (never installed); prints the models' directory. For scripts/assimp-models and
# scripts/openflight-peer.
sv_assimp_models() {
  local debs=$SV_ROOT/build-data/debs root=$SV_ROOT/build-data/root
  local models=$root/usr/share/assimp/models
  if [[ ! -d $models ]]; then
    mkdir -p "$debs" "$root"
    if ! compgen -G "$debs/assimp-testmodels_*.deb" >/dev/null; then
      echo "downloading assimp-testmodels into $debs" >&2
      (cd "$debs" && apt-get download -qq -o APT::Sandbox::User=root assimp-testmodels) ||
        { apt-get update -qq && (cd "$debs" && apt-get download -qq -o APT::Sandbox::User=root assimp-testmodels); }
    fi
    dpkg -x "$(compgen -G "$debs/assimp-testmodels_*.deb" | head -1)" "$root"
  fi
  echo "$models"
}
