#!/usr/bin/env bash
# Create (or refresh) the roughfe environment on a fresh Debian 12 machine.
#
#   bash tools/bootstrap.sh [EXTRAS]      EXTRAS defaults to "io,design,study,test"
#
# Idempotent and fast when nothing changed: a stamp in .venv records the hash of the
# files that define the environment and the extras installed; when the hash matches and
# the extras asked for are among those installed, nothing is done.
#
# Facts measured on Debian 12 that shape this script:
#  * dolfinx 0.5.2, petsc4py, mpi4py, gmsh, h5py, meshio and scipy come from Debian
#    (python3-* packages). The venv is made from Debian's /usr/bin/python3 with
#    --system-site-packages so that it sees them; the machine's default python3 is a
#    different interpreter and does not.
#  * pip pulls numpy 2.x by default and then dolfinx, petsc4py, scipy and h5py fail to
#    import ("numpy.dtype size changed"). tools/constraints.txt pins numpy==1.24.2 and
#    .venv/pip.conf points every later pip call at it.
#  * dolfinx sets RTLD_GLOBAL dlopen flags; a PyPI h5py imported after dolfinx fails
#    ("Not a datatype"). SurfaceTopography declares h5py, so it is installed with
#    --no-deps and its other requirements come from the "io" extra of pyproject.toml.
#  * The vtk wheel renders off-screen through EGL (libegl1) or OSMesa (libosmesa6);
#    with neither it segfaults.
set -euo pipefail
cd "$(dirname "$0")/.."
EXTRAS="${1:-io,design,study,test}"
VENV=.venv
APT_PACKAGES="python3-dolfinx python3-petsc4py python3-mpi4py python3-gmsh python3-meshio \
python3-h5py python3-scipy python3-pytest python3-venv python3-pip libegl1 libosmesa6"

missing=""
for p in $APT_PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "[bootstrap] installing Debian packages:$missing"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi

# the checkout's path is part of the stamp: the editable install maps `roughfe` to one
# checkout, so a venv shared with (or moved from) another checkout is re-pointed here.
# The stamp's second line lists the extras installed: a call asking for a subset of them
# (make test after make bench) does nothing, and a call asking for more installs the union,
# so that two targets with different extras never undo each other's install.
stamp_value="$(cat pyproject.toml tools/bootstrap.sh tools/constraints.txt | sha256sum | cut -c1-16)-$(pwd)"
stamp="$VENV/.roughfe-stamp"
installed=""
if [ -x "$VENV/bin/python" ] && [ -f "$stamp" ] && [ "$(head -n 1 "$stamp")" = "$stamp_value" ]; then
  installed="$(sed -n 2p "$stamp")"
  new=""
  for e in ${EXTRAS//,/ }; do
    case ",$installed," in *,"$e",*) ;; *) new="$new $e" ;; esac
  done
  [ -z "$new" ] && exit 0
fi
EXTRAS="$(echo "$installed,$EXTRAS" | tr ',' '\n' | sed '/^$/d' | sort -u | paste -sd, -)"

if [ ! -x "$VENV/bin/python" ]; then
  echo "[bootstrap] creating $VENV from /usr/bin/python3 (--system-site-packages)"
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
fi
printf '[global]\nconstraint = %s\ndisable-pip-version-check = true\n' "$(pwd)/tools/constraints.txt" > "$VENV/pip.conf"

echo "[bootstrap] installing roughfe[$EXTRAS] (numpy pinned to Debian's 1.24.2)"
"$VENV/bin/python" -m pip install -q -e ".[$EXTRAS]"
case ",$EXTRAS," in
  *,io,*) "$VENV/bin/python" -m pip install -q --no-deps "surfacetopography==1.18.2" ;;
esac
"$VENV/bin/python" - <<'PY'
import numpy, scipy, h5py, dolfinx
assert numpy.__version__ == "1.24.2", numpy.__version__
assert h5py.__file__.startswith("/usr/lib/python3/dist-packages"), h5py.__file__
print(f"[bootstrap] ok: numpy {numpy.__version__}, dolfinx {dolfinx.__version__}, h5py from Debian")
PY
printf '%s\n%s\n' "$stamp_value" "$EXTRAS" > "$stamp"
