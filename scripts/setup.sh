#!/usr/bin/env bash
# Installs everything colmap-lidar needs on a fresh Debian 12 machine (run as root). Idempotent:
# packages already present are skipped, and COLMAP 3.10 is built once into a cache prefix.
#
#   COLMAP_LIDAR_COLMAP_PREFIX   where COLMAP 3.10 is installed (default ~/.cache/colmap-lidar/colmap-3.10)
#   COLMAP_LIDAR_SKIP_APT=1      do not touch apt (for users who installed the packages themselves)
set -euo pipefail

readonly kColmapSha256="61850f323e201ab6a1abbfb0e4a8b3ba1c4cedbf55e0a5716bdea1df8ae1813a"
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kPackages=(
  cmake ninja-build g++ pkg-config dpkg-dev
  libeigen3-dev libceres-dev libgoogle-glog-dev libgflags-dev
  libboost-program-options-dev libboost-filesystem-dev libboost-graph-dev libboost-system-dev
  libfreeimage-dev libflann-dev libmetis-dev libsqlite3-dev sqlite3 libsuitesparse-dev libglew-dev
  libpcl-dev libopencv-dev libgtest-dev libgmock-dev libomp-dev
  libnanoflann-dev nlohmann-json3-dev
  clang libfuzzer-14-dev ccache
)

log() { printf '[setup] %s\n' "$*"; }

sudo_if_needed() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

install_packages() {
  if [ "${COLMAP_LIDAR_SKIP_APT:-0}" = 1 ]; then return; fi
  local missing=()
  for p in "${kPackages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    log "all ${#kPackages[@]} Debian packages present"
    return
  fi
  log "installing ${#missing[@]} Debian packages: ${missing[*]}"
  sudo_if_needed apt-get update -qq
  DEBIAN_FRONTEND=noninteractive sudo_if_needed apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

colmap_installed() {
  [ -f "$kColmapPrefix/share/colmap/colmap-config.cmake" ] && [ -x "$kColmapPrefix/bin/colmap" ]
}

user_colmap_found() {
  local d prefixes="${CMAKE_PREFIX_PATH:-}"
  for d in ${colmap_DIR:-} ${prefixes//:/ }; do
    for f in "$d/colmap-config.cmake" "$d/share/colmap/colmap-config.cmake"; do
      if [ -f "$f" ] && grep -q 'BundleAdjuster\|colmap' "$f" && \
         grep -rqs '3\.10' "$(dirname "$f")"/colmap-config-version.cmake; then
        log "using the user's COLMAP 3.10 at $(dirname "$f")"
        return 0
      fi
    done
  done
  return 1
}

fetch_colmap_source() {
  local work="$1"
  local list=/etc/apt/sources.list.d/colmap-lidar-trixie-src.sources
  if [ ! -f "$list" ]; then
    log "adding a deb-src entry for trixie (source packages only) at $list"
    sudo_if_needed tee "$list" >/dev/null <<'SRC'
# Added by colmap-lidar scripts/setup.sh: source packages only, to fetch COLMAP 3.10's upstream tarball.
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: trixie
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
    sudo_if_needed apt-get update -qq
  fi
  (cd "$work" && { apt-get source --download-only --tar-only colmap=3.10-2 >/dev/null 2>&1 ||
                   apt-get source --download-only --tar-only colmap/trixie >/dev/null; })
  local tarball
  tarball=$(ls "$work"/colmap_3.10*.orig.tar.* | head -n 1)
  local sum
  sum=$(sha256sum "$tarball" | cut -d' ' -f1)
  if [ "$sum" != "$kColmapSha256" ]; then
    echo "[setup] ERROR: $tarball has sha256 $sum, expected $kColmapSha256" >&2
    exit 1
  fi
  log "verified $tarball"
  mkdir -p "$work/src"
  tar -xf "$tarball" -C "$work/src" --strip-components=1
}

build_colmap() {
  if colmap_installed; then
    log "COLMAP 3.10 already installed at $kColmapPrefix"
    return
  fi
  if user_colmap_found; then return; fi
  local work
  work=$(mktemp -d "${TMPDIR:-/tmp}/colmap-lidar-colmap.XXXXXX")
  trap 'rm -rf "$work"' RETURN
  fetch_colmap_source "$work"
  log "building COLMAP 3.10 (about 12 minutes on 2 cores) into $kColmapPrefix"
  local start=$SECONDS
  cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$kColmapPrefix.partial" \
    -DGUI_ENABLED=OFF -DOPENGL_ENABLED=OFF -DCUDA_ENABLED=OFF -DCGAL_ENABLED=OFF \
    -DTESTS_ENABLED=OFF -DIPO_ENABLED=OFF >"$work/configure.log" 2>&1 ||
    { tail -n 40 "$work/configure.log" >&2; exit 1; }
  cmake --build "$work/build" -j "$(nproc)" >"$work/build.log" 2>&1 ||
    { tail -n 60 "$work/build.log" >&2; exit 1; }
  rm -rf "$kColmapPrefix.partial"
  cmake --install "$work/build" >/dev/null
  # Install under a temporary name and rename: an interrupted build never looks finished.
  # The config files record the install prefix, so rewrite it.
  grep -rl "$kColmapPrefix.partial" "$kColmapPrefix.partial" 2>/dev/null |
    xargs -r sed -i "s|$kColmapPrefix.partial|$kColmapPrefix|g"
  rm -rf "$kColmapPrefix"
  mv "$kColmapPrefix.partial" "$kColmapPrefix"
  log "COLMAP 3.10 built in $((SECONDS - start)) s"
}

install_packages
mkdir -p "$(dirname "$kColmapPrefix")"
build_colmap
log "done; COLMAP prefix: $kColmapPrefix"
