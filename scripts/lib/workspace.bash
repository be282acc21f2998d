# Shared by the scripts in scripts/: Debian's interpreter first, the catkin workspace beside the
# checkout (.ws/, ignored by git), build and source helpers. Source it; do not run it.

# The pyenv python3 on PATH lacks catkin_pkg/rospy and breaks catkin (shared/notes/debian-ros.md).
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
unset PYTHONPATH PYTHONHOME

QS_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
QS_WS=${QS_WS:-$QS_ROOT/.ws}
QS_JOBS=${QS_JOBS:-$(nproc)}

# Creates the workspace (a symlink to the checkout, nothing copied) and builds it.
# Extra arguments go to catkin_make (e.g. a target such as `tests`).
qs_build() {
  mkdir -p "$QS_WS/src"
  ln -sfn "$QS_ROOT" "$QS_WS/src/quadric_slam"
  (cd "$QS_WS" && catkin_make -DCMAKE_BUILD_TYPE=Release -j"$QS_JOBS" "$@")
}

# Sources the built workspace (setup.bash is not `set -u` clean).
qs_source() {
  set +u
  # shellcheck disable=SC1091
  source "$QS_WS/devel/setup.bash"
  set -u
}

# Runs one of the package's tools (.ws/devel/lib/quadric_slam/NAME) with the remaining arguments,
# building the workspace first when the binary is missing.
qs_exec_tool() {
  local name=$1
  shift
  local binary="$QS_WS/devel/lib/quadric_slam/$name"
  if [ ! -x "$binary" ]; then
    echo "$name: building the workspace in $QS_WS (first use)" >&2
    "$QS_ROOT/scripts/setup" >&2
    qs_build >&2
  fi
  qs_source
  exec "$binary" "$@"
}
