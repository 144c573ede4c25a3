#!/usr/bin/env bash
# Run a command with numpy, scipy and PETSc on the *other* BLAS/LAPACK than the one this
# machine's numpy loads, without installing anything system-wide:
#
#   bash tools/other_blas.sh CMD [ARGS...]        (make test-other-blas)
#
# Why: Debian's numpy loads whatever libblas.so.3 / liblapack.so.3 the alternatives
# system points to: the reference BLAS on a minimal Debian 12 (this project's machine),
# OpenBLAS where libopenblas0 is installed, and pip's numpy wheels bundle OpenBLAS. The
# rounding of the two differs, and a result that depends on it is a defect: with OpenBLAS
# 11 tests failed in round 2, session 41 (exact floats of the reference BLAS's rounding,
# and searches that went elsewhere). This script fetches the other library's Debian
# package with `apt-get download` (no root needed), unpacks it into .venv/other-blas/ and
# runs CMD with it first on LD_LIBRARY_PATH (one BLAS thread: the suite runs on -n 2).
#
# Exit status: that of CMD; 3 when the other BLAS cannot be had here (no apt-get, no
# network, or a BLAS this script does not know): .ci/run reports that as not run.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
[ $# -gt 0 ] || { echo "usage: bash tools/other_blas.sh CMD [ARGS...]" >&2; exit 2; }

# which BLAS a numpy matrix product and a LAPACK call really load (the mapped libraries)
loaded_blas() {
  "$PY" - <<'EOF'
import numpy as np
a = np.ones((64, 64))
np.linalg.solve(a + 64 * np.eye(64), a[0]) @ a
libs = {line.split()[-1] for line in open("/proc/self/maps") if ".so" in line}
if any("openblas" in lib for lib in libs):
    print("openblas")
elif any("/blas/libblas" in lib for lib in libs):
    print("reference")
else:
    print("unknown:" + ",".join(sorted(lib for lib in libs if "blas" in lib or "lapack" in lib)))
EOF
}

multiarch="$("$PY" -c 'import sysconfig; print(sysconfig.get_config_var("MULTIARCH") or "")')"
now="$(loaded_blas)"
case "$now" in
  reference) other=openblas; packages="libopenblas0-pthread"
             libdirs="usr/lib/$multiarch/openblas-pthread" ;;
  openblas)  other=reference; packages="libblas3 liblapack3"
             libdirs="usr/lib/$multiarch/blas:usr/lib/$multiarch/lapack" ;;
  *) echo "[other-blas] not run: numpy loads a BLAS this script does not know ($now)" >&2
     exit 3 ;;
esac

root=".venv/other-blas/$other"
if [ ! -d "$root/usr" ]; then
  command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null || {
    echo "[other-blas] not run: apt-get/dpkg-deb are missing (needed to fetch $packages)" >&2
    exit 3; }
  tmp="$(mktemp -d .venv/other-blas.XXXXXX)"
  trap 'rm -rf "$tmp"' EXIT
  if ! (cd "$tmp" && apt-get download $packages >download.log 2>&1); then
    echo "[other-blas] not run: 'apt-get download $packages' failed:" >&2
    tail -n 3 "$tmp/download.log" >&2
    exit 3
  fi
  for deb in "$tmp"/*.deb; do dpkg-deb -x "$deb" "$tmp/root"; done
  mkdir -p .venv/other-blas
  rm -rf "$root"
  mv "$tmp/root" "$root"         # complete or absent: an interrupted fetch is not kept
fi

path=""
IFS=: read -ra dirs <<<"$libdirs"
for d in "${dirs[@]}"; do path="${path:+$path:}$PWD/$root/$d"; done
export LD_LIBRARY_PATH="$path${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export OPENBLAS_NUM_THREADS=1
got="$(loaded_blas)"
if [ "$got" != "$other" ]; then
  echo "[other-blas] not run: with $root on LD_LIBRARY_PATH numpy still loads '$got'" >&2
  exit 3
fi
echo "[other-blas] numpy loads $other (this machine's default: $now); running: $*"
exec "$@"
