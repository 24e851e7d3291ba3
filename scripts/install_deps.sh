#!/usr/bin/env bash
# Installs the Debian 12 packages saloam needs, only those missing.
# Idempotent: runs `apt-get update` once, and only when something is missing.
set -euo pipefail

packages=(
  g++ cmake make ninja-build pkg-config ccache
  libeigen3-dev libceres-dev libnanoflann-dev libtbb-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  libcairo2-dev libgtest-dev libgmock-dev libbenchmark-dev
  robin-map-dev
  libjs-three libcpp-httplib-dev chromium  # saloam view: three.js, its --serve server, the headless page test
  libtorch-dev  # saloam sgpr-train (optional: without it the rest builds and the trainer is left out)
  liblzf-dev  # binary_compressed PCD (optional: without it such files are an error that says so)
  librosbag-storage-dev  # ROS 1 bags (optional: without it bags are an error that says so)
  libsqlite3-dev libzstd-dev liblz4-dev  # ROS 2 recordings: rosbag2 .db3 (SQLite) and MCAP chunks (zstd, LZ4)
  libpcap-dev  # sensor packet captures (.pcap: Ouster, Velodyne)
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module `import saloam` and its tests (python/)
  python3-dask python3-distributed  # saloam fleet: fleet mapping on Dask (docs/fleet.md)
  python3-torch  # scripts/segnet_torch.py: SegNet trained with PyTorch (a GPU where there is one) and its test
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "Installing missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "error: run as root or install sudo" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
# The downloaded packages (1.5 GB with libtorch) are not needed once installed.
$SUDO apt-get clean
