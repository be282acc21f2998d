#!/usr/bin/env bash
# Odometry benchmark: our pipeline (odometry only, and full SLAM) against Open3D on full-length
# synthetic sequences driven by the real TUM fr1_desk, fr1_xyz, fr1_room ... motion-capture
# trajectories (the desk scene; fr1_room in config/scenes/room_fr1.yaml, a room around its path), at full rate and sub-sampled (every Nth frame: large steps between frames), and
# optionally on the real 7-Scenes kitchen.
#
#   test/bench/odometry_benchmark.sh [--out DIR] [--seconds S] [--sequences "fr1_desk fr1_xyz"]
#                                    [--methods "legacy_hybrid t_point_to_plane ..."]
#                                    [--max-frames N] [--open3d-max-frames N] [--regenerate]
#                                    [--no-open3d] [--sample-every "1 10 20"]
#                                    [--open3d-sample-every "10 20"] [--no-slam]
#                                    [--depth-model harsh|nguyen] [--kitchen] [--kitchen-only]
#                                    [--guess-off]
#
#   --out DIR       where sequences and results go (default out/bench, ignored by git)
#   --seconds S     sequence length given to scripts/synth (default 40: longer than both trajectories,
#                   so each sequence covers its whole ground truth: 702 and 903 frames at 30 Hz)
#   --sequences     which ground-truth trajectories drive the generator (fr1_desk fr1_xyz fr1_room
#                   fr2_desk fr2_xyz; default "fr1_desk fr1_xyz")
#   --methods       Open3D methods (see test/bench/open3d_odometry.py; default all three)
#   --max-frames N  only the first N frames of each sequence (quick runs; default all)
#   --open3d-max-frames N
#                   Open3D only on the first N frames (it runs at 0.2-1.5 s per frame single-threaded
#                   here); ours then also runs on those N frames, as an extra like-for-like row
#   --regenerate    re-render sequences that already exist
#   --no-open3d     only our pipeline
#   --sample-every "1 10 20"
#                   frame rates to run: every Nth frame of each sequence (default "1"). A sub-sampled
#                   run reads DIR/SEQ/every_N: depth.txt with every Nth line (from the first), the
#                   images, rgb.txt and groundtruth.txt linked; ours and Open3D read the same list
#   --open3d-sample-every "10 20"
#                   Open3D only at these of the rates (default: all of --sample-every)
#   --no-slam       only odometry-only runs of ours (default: also scripts/run_bag without
#                   --odometry-only, whose map_ate_rmse_m is the SLAM ATE and whose ate_rmse_m is
#                   the odometry inside the full pipeline, with the quadric motion guess; the
#                   odometry-only run has no segmentation, so no guess: ICP from the prior alone)
#   --depth-model M synth's sensor model (default harsh: the segmentation issue's model, synth's
#                   default too; nguyen is the milder one)
#   --kitchen       also the real 7-Scenes kitchen (../shared/data/7scenes_redkitchen, depth only:
#                   no Open3D, which needs colour), at the same rates
#   --kitchen-only  only the kitchen
#   --guess-off     also a SLAM run with the quadric motion guess off (config copy with
#                   quadric_motion_guess: false): its accuracy and odometry-stage time beside the
#                   default's (the guess's cost per frame)
#
# Steps per sequence: scripts/synth (TUM folder, no bag) -> per rate: scripts/run_bag
# --odometry-only, scripts/run_bag (SLAM) -> scripts/evaluate (ATE RMSE, RPE) and timing.json;
# then every Open3D method: a direction check on the first frames against groundtruth.txt, the full
# run, the same evaluator. Prints two Markdown tables (every run; and sequence x rate -> ATE of
# each method and time per frame) and writes them to DIR/odometry_benchmark.md. Open3D comes from
# Debian's python3-open3d (installed here when missing) and runs with /usr/bin/python3 and
# OMP_NUM_THREADS=1 (our tracker is single-threaded). Timing is wall clock on a shared machine: the
# table header records uptime's load average.
set -euo pipefail
source "$(dirname "$0")/../../scripts/lib/workspace.bash"

out="$QS_ROOT/out/bench"
seconds=40
sequences="fr1_desk fr1_xyz"
methods="legacy_hybrid t_point_to_plane icp_point_to_plane"
max_frames=0
o3d_max_frames=0
regenerate=0
open3d=1
rates="1"
o3d_rates=""
slam=1
depth_model=harsh
kitchen=0
synthetic=1
guess_off=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --sequences) sequences=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --max-frames) max_frames=$2; shift 2 ;;
    --open3d-max-frames) o3d_max_frames=$2; shift 2 ;;
    --regenerate) regenerate=1; shift ;;
    --no-open3d) open3d=0; shift ;;
    --sample-every) rates=$2; shift 2 ;;
    --open3d-sample-every) o3d_rates=$2; shift 2 ;;
    --no-slam) slam=0; shift ;;
    --depth-model) depth_model=$2; shift 2 ;;
    --kitchen) kitchen=1; shift ;;
    --kitchen-only) kitchen=1; synthetic=0; shift ;;
    --guess-off) guess_off=1; shift ;;
    -h|--help) sed -n '2,53p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "odometry_benchmark: unknown option $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
gt_dir="$QS_ROOT/../shared/data/tum_groundtruth"
[ -d "$gt_dir" ] || gt_dir=/work/shared/data/tum_groundtruth
py=/usr/bin/python3
o3d_script="$QS_ROOT/test/bench/open3d_odometry.py"

sudo_cmd=""
[ "$(id -u)" -eq 0 ] || sudo_cmd=sudo
if [ "$open3d" -eq 1 ] && ! "$py" -c 'import open3d' 2>/dev/null; then
  echo "odometry_benchmark: installing python3-open3d" >&2
  $sudo_cmd apt-get install -y --no-install-recommends python3-open3d >&2
fi
# step_errors.py needs numpy (python3-open3d brings it; without Open3D it may be missing).
if ! "$py" -c 'import numpy' 2>/dev/null; then
  echo "odometry_benchmark: installing python3-numpy" >&2
  $sudo_cmd apt-get install -y --no-install-recommends python3-numpy >&2
fi
for tool in synth run_bag evaluate; do
  if [ ! -x "$QS_WS/devel/lib/quadric_slam/$tool" ]; then
    echo "odometry_benchmark: building the workspace ($tool missing)" >&2
    qs_build >&2
    break
  fi
done

# Writes one result row (tab-separated) to $out/rows.tsv:
# sequence rate method ate rpe frames pairs failures odo_median odo_p95 prep_median prep_p95
# frame_ms status wrong_steps
rows="$out/rows.tsv"
: >"$rows"

evaluate_row() {  # sequence rate method trajectory timing.json kind(ours|open3d) gt [status]
  local seq=$1 rate=$2 method=$3 traj=$4 timing=$5 kind=$6 gt=$7 status=${8:--} eval_out
  eval_out=$("$QS_ROOT/scripts/evaluate" --gt "$gt" --est "$traj")
  echo "$eval_out" >"${traj%.txt}.eval.txt"
  local ate rpe pairs
  ate=$(awk '$1 == "ate_rmse_m" {print $2}' <<<"$eval_out")
  rpe=$(awk '$1 == "rpe_m_per_s" {print $2}' <<<"$eval_out")
  pairs=$(awk '$1 == "pairs" {print $2}' <<<"$eval_out")
  # Consecutive-frame steps off by more than 5 cm or 5 degrees (test/bench/step_errors.py).
  local wrong
  wrong=$("$py" "$QS_ROOT/test/bench/step_errors.py" --gt "$gt" --est "$traj" |
    awk '$1 == "steps" {n = $2} $1 == "wrong_steps" {w = $2} END {print w "/" n}')
  "$py" - "$timing" "$kind" "$seq" "$rate" "$method" "$ate" "$rpe" "$pairs" "$status" "$wrong" \
    >>"$rows" <<'PY'
import json, sys
timing, kind, seq, rate, method, ate, rpe, pairs, status, wrong = sys.argv[1:]
t = json.load(open(timing))
st = t["stages"]
def get(stage, key):
    return "%.2f" % st[stage][key] if stage in st else "-"
if kind == "ours":
    odo, prep, failures = "odometry", "normals", "-"
    # Whole per-frame cost of the run (reading, normals, segmentation, odometry, mapping).
    frame_ms = "%.1f" % (1e3 * t["wall_s"] / max(t["frames"], 1)) if "wall_s" in t else "-"
else:
    odo, prep, failures = "total", "prep", str(t.get("failures", "-"))
    frame_ms = get("total", "median_ms")
print("\t".join([seq, rate, method, ate, rpe, str(t["frames"]), pairs, failures,
                 get(odo, "median_ms"), get(odo, "p95_ms"), get(prep, "median_ms"),
                 get(prep, "p95_ms"), frame_ms, status, wrong]))
PY
}

# A view of a TUM folder at every Nth frame: depth.txt keeps every Nth frame line from the first
# (comments kept); images, rgb.txt (each depth frame finds its colour by stamp) and
# groundtruth.txt are linked.
subsample_folder() {  # source_dir n dest_dir
  local src=$1 n=$2 dst=$3 item
  mkdir -p "$dst"
  for item in depth rgb rgb.txt groundtruth.txt; do
    [ -e "$src/$item" ] && ln -sfn "$src/$item" "$dst/$item"
  done
  awk -v n="$n" '/^#/ {print; next} NF {if (k % n == 0) print; k++}' "$src/depth.txt" \
    >"$dst/depth.txt"
}

# The config with the quadric motion guess off, for --guess-off.
guess_off_config="$out/config_guess_off"
if [ "$guess_off" -eq 1 ]; then
  rm -rf "$guess_off_config"
  cp -r "$QS_ROOT/config" "$guess_off_config"
  sed -i 's/^quadric_motion_guess: true/quadric_motion_guess: false/' \
    "$guess_off_config/odometry.yaml"
  grep -q '^quadric_motion_guess: false' "$guess_off_config/odometry.yaml" ||
    { echo "odometry_benchmark: could not turn the guess off in odometry.yaml" >&2; exit 1; }
fi

# Our runs on one folder: odometry only, then SLAM (map and its odometry), then SLAM without the
# guess (--guess-off). extra: run_bag options (intrinsics).
run_ours() {  # seq rate dir gt extra...
  local seq=$1 rate=$2 dir=$3 gt=$4
  shift 4
  local limit=()
  [ "$max_frames" -gt 0 ] && limit=(--max-frames "$max_frames")
  echo "== $seq every $rate: ours (scripts/run_bag --odometry-only)" >&2
  mkdir -p "$dir/ours"
  "$QS_ROOT/scripts/run_bag" "$dir" --out "$dir/ours" --odometry-only --gt "$gt" "${limit[@]}" "$@" \
    >"$dir/ours/run_bag.log" 2>&1 || { cat "$dir/ours/run_bag.log" >&2; exit 1; }
  evaluate_row "$seq" "$rate" "ours odometry-only" "$dir/ours/trajectory.txt" \
    "$dir/ours/timing.json" ours "$gt" "$(status_of "$dir/ours/run_bag.log")"
  [ "$slam" -eq 1 ] || return 0
  local variants=("slam:")
  [ "$guess_off" -eq 1 ] && variants+=("slam_guess_off:$guess_off_config")
  local variant name config
  for variant in "${variants[@]}"; do
    name=${variant%%:*}
    config=${variant#*:}
    local config_args=()
    [ -n "$config" ] && config_args=(--config "$config")
    echo "== $seq every $rate: ours ($name: scripts/run_bag)" >&2
    mkdir -p "$dir/$name"
    "$QS_ROOT/scripts/run_bag" "$dir" --out "$dir/$name" --gt "$gt" "${limit[@]}" \
      "${config_args[@]}" "$@" >"$dir/$name/run_bag.log" 2>&1 ||
      { cat "$dir/$name/run_bag.log" >&2; exit 1; }
    local label="ours SLAM"
    [ "$name" = slam ] || label="ours SLAM, guess off"
    local status
    status=$(status_of "$dir/$name/run_bag.log")
    evaluate_row "$seq" "$rate" "$label (odometry)" "$dir/$name/trajectory_odom.txt" \
      "$dir/$name/timing.json" ours "$gt" "$status"
    evaluate_row "$seq" "$rate" "$label (map)" "$dir/$name/trajectory.txt" \
      "$dir/$name/timing.json" ours "$gt" "$status"
  done
}

status_of() {  # run_bag.log -> "ok/degenerate/lost"
  awk '$1 == "tracking" && $2 == "ok" {print $3 "/" $5 "/" $7}' "$1"
}

run_open3d() {  # seq rate dir
  local seq=$1 rate=$2 dir=$3 method
  local o3d_frames=$max_frames
  if [ "$o3d_max_frames" -gt 0 ] && { [ "$max_frames" -eq 0 ] || [ "$o3d_max_frames" -lt "$max_frames" ]; }; then
    o3d_frames=$o3d_max_frames
    echo "== $seq every $rate: ours on the first $o3d_frames frames (like for like with Open3D)" >&2
    mkdir -p "$dir/ours_first$o3d_frames"
    "$QS_ROOT/scripts/run_bag" "$dir" --out "$dir/ours_first$o3d_frames" --odometry-only \
      --max-frames "$o3d_frames" >"$dir/ours_first$o3d_frames/run_bag.log" 2>&1 ||
      { cat "$dir/ours_first$o3d_frames/run_bag.log" >&2; exit 1; }
    evaluate_row "$seq" "$rate" "ours odometry-only (first $o3d_frames frames)" \
      "$dir/ours_first$o3d_frames/trajectory.txt" "$dir/ours_first$o3d_frames/timing.json" ours \
      "$dir/groundtruth.txt" "$(status_of "$dir/ours_first$o3d_frames/run_bag.log")"
  fi
  for method in $methods; do
    echo "== $seq every $rate: open3d $method" >&2
    mkdir -p "$dir/open3d"
    # Direction check first (on the full-rate frames): the chained motions must match
    # groundtruth.txt, not its inverse.
    if [ "$rate" -eq 1 ]; then
      "$py" "$o3d_script" --seq "$dir" --method "$method" --out /dev/null --check-direction 10 \
        >"$dir/open3d/$method.check.log" 2>&1 || { cat "$dir/open3d/$method.check.log" >&2; exit 1; }
      tail -n 1 "$dir/open3d/$method.check.log" >&2
    fi
    o3d_args=(--seq "$dir" --method "$method" --out "$dir/open3d/$method.txt"
              --timing "$dir/open3d/$method.timing.json")
    [ "$o3d_frames" -gt 0 ] && o3d_args+=(--max-frames "$o3d_frames")
    "$py" "$o3d_script" "${o3d_args[@]}" >&2
    local label="open3d $method"
    [ "$o3d_frames" -gt 0 ] && label="$label (first $o3d_frames frames)"
    evaluate_row "$seq" "$rate" "$label" "$dir/open3d/$method.txt" \
      "$dir/open3d/$method.timing.json" open3d "$dir/groundtruth.txt"
  done
}

rate_dir() {  # base_dir rate -> the folder to read (the base itself at rate 1)
  if [ "$2" -eq 1 ]; then
    echo "$1"
  else
    subsample_folder "$1" "$2" "$1/every_$2"
    echo "$1/every_$2"
  fi
}

[ -n "$o3d_rates" ] || o3d_rates=$rates
load_before=$(uptime)
# The scene a trajectory is rendered in: fr1_room walks around a whole room (config/scenes/
# room_fr1.yaml surrounds its path); the other trajectories look at a desk (desk.yaml).
scene_for() {
  case "$1" in
    fr1_room) echo "$QS_ROOT/config/scenes/room_fr1.yaml" ;;
    *) echo "$QS_ROOT/config/scenes/desk.yaml" ;;
  esac
}

if [ "$synthetic" -eq 1 ]; then
  for seq in $sequences; do
    gt_file="$gt_dir/rgbd_dataset_${seq/fr/freiburg}-groundtruth.txt"
    [ -f "$gt_file" ] || { echo "odometry_benchmark: no ground truth $gt_file" >&2; exit 1; }
    base="$out/$seq"
    if [ "$regenerate" -eq 1 ] || [ ! -f "$base/depth.txt" ] || [ ! -f "$base/groundtruth.txt" ]; then
      rm -rf "$base"
      echo "== $seq: rendering $seconds s along $(basename "$gt_file"), depth model $depth_model" >&2
      "$QS_ROOT/scripts/synth" --out "$base" --scene "$(scene_for "$seq")" \
        --trajectory "$gt_file" --seconds "$seconds" \
        --no-bag --no-labels --name "$seq" --depth-model "$depth_model" --threads "$QS_JOBS" \
        >"$out/$seq.synth.log" 2>&1
    fi
    for rate in $rates; do
      dir=$(rate_dir "$base" "$rate")
      echo "== $seq every $rate: $(grep -vc '^#' "$dir/depth.txt") frames" >&2
      run_ours "$seq" "$rate" "$dir" "$dir/groundtruth.txt"
      if [ "$open3d" -eq 1 ] && [[ " $o3d_rates " == *" $rate "* ]]; then
        run_open3d "$seq" "$rate" "$dir"
      fi
    done
  done
fi

if [ "$kitchen" -eq 1 ]; then
  kitchen_src="$QS_ROOT/../shared/data/7scenes_redkitchen"
  [ -d "$kitchen_src" ] || kitchen_src=/work/shared/data/7scenes_redkitchen
  [ -f "$kitchen_src/depth.txt" ] || { echo "odometry_benchmark: no kitchen in $kitchen_src" >&2; exit 1; }
  base="$out/kitchen"
  mkdir -p "$base"
  for item in depth depth.txt groundtruth.txt; do ln -sfn "$kitchen_src/$item" "$base/$item"; done
  for rate in $rates; do
    dir=$(rate_dir "$base" "$rate")
    echo "== kitchen every $rate: $(grep -vc '^#' "$dir/depth.txt") frames" >&2
    run_ours kitchen "$rate" "$dir" "$dir/groundtruth.txt" --intrinsics 585,585,320,240
  done
fi
load_after=$(uptime)

"$py" - "$rows" "$out/odometry_benchmark.md" "$load_before" "$load_after" "$(nproc)" \
  "$depth_model" <<'EOF'
import sys
rows_path, md_path, before, after, cores, depth_model = sys.argv[1:]
rows = [l.rstrip("\n").split("\t") for l in open(rows_path) if l.strip()]
lines = [
    "# Odometry benchmark (frame-to-keyframe / frame-to-frame; synthetic scenes (the desk; fr1_room in a room around its path) along "
    "real TUM trajectories, depth model %s; the real 7-Scenes kitchen)" % depth_model,
    "",
    "Machine: %s cores, shared. Load at start: `%s`. Load at end: `%s`." % (cores, before.strip(), after.strip()),
    "",
    "Rate N: every Nth frame of the sequence. Ours: odometry-only = run_bag --odometry-only (no "
    "segmentation, so ICP from the constant-velocity prior alone); SLAM (odometry) = the odometry "
    "inside the full pipeline (with the quadric motion guess); SLAM (map) = the mapper's "
    "trajectory. Status = ok/degenerate/lost frames of the run. Timing: ours = the odometry "
    "stage of timing.json (prep = the normals stage), frame ms = the run's wall time per frame "
    "(everything, PNG reading included); Open3D = the whole per-frame cost from decoded images "
    "(prep = RGBD image / cloud + normals, then the odometry call), OMP_NUM_THREADS=1. Wrong steps: "
    "consecutive estimated frames whose relative motion is off the truth's by more than 5 cm or "
    "5 degrees, of all steps (test/bench/step_errors.py; a lost frame holds its pose, so its step "
    "counts as wrong when the camera moved).",
    "",
    "| sequence | rate | method | ATE RMSE (m) | RPE (m/s) | frames | ATE pairs | failed | odometry median ms | odometry p95 ms | prep median ms | prep p95 ms | frame ms | status | wrong steps |",
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
]
for r in rows:
    lines.append("| " + " | ".join(r) + " |")

# Pivot: sequence x rate -> ATE of each method, and frame time of each.
methods = []
for r in rows:
    if r[2] not in methods:
        methods.append(r[2])
cells = {}
for r in rows:
    cells[(r[0], r[1], r[2])] = r
keys = []
for r in rows:
    if (r[0], r[1]) not in keys:
        keys.append((r[0], r[1]))
def fmt(r):
    try:
        ate = "%.1f cm" % (100 * float(r[3]))
    except ValueError:
        ate = r[3]
    return "%s (%s ms)" % (ate, r[12])
lines += ["", "## ATE RMSE by sequence and rate (frame ms in brackets)", "",
          "| sequence | rate | " + " | ".join(methods) + " |",
          "|---|---|" + "---|" * len(methods)]
for seq, rate in keys:
    lines.append("| %s | %s | " % (seq, rate) + " | ".join(
        fmt(cells[(seq, rate, m)]) if (seq, rate, m) in cells else "-" for m in methods) + " |")
text = "\n".join(lines) + "\n"
open(md_path, "w").write(text)
print(text)
EOF
echo "odometry_benchmark: table written to $out/odometry_benchmark.md" >&2
