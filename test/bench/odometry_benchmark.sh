#!/usr/bin/env bash
# Odometry benchmark: our odometry-only pipeline against Open3D on full-length synthetic desk
# sequences driven by the real TUM fr1_desk and fr1_xyz motion-capture trajectories.
#
#   test/bench/odometry_benchmark.sh [--out DIR] [--seconds S] [--sequences "fr1_desk fr1_xyz"]
#                                    [--methods "legacy_hybrid t_point_to_plane ..."]
#                                    [--max-frames N] [--open3d-max-frames N] [--regenerate]
#                                    [--no-open3d]
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
#
# Steps per sequence: scripts/synth (TUM folder, no bag) -> scripts/run_bag --odometry-only ->
# scripts/evaluate (ATE RMSE, RPE) and timing.json (odometry and normals stages); then every Open3D
# method: a direction check on the first frames against groundtruth.txt, the full run, the same
# evaluator. Prints a Markdown table and writes it to DIR/odometry_benchmark.md. Open3D comes from
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
    -h|--help) sed -n '2,30p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "odometry_benchmark: unknown option $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
gt_dir="$QS_ROOT/../shared/data/tum_groundtruth"
[ -d "$gt_dir" ] || gt_dir=/work/shared/data/tum_groundtruth
py=/usr/bin/python3
o3d_script="$QS_ROOT/test/bench/open3d_odometry.py"

if [ "$open3d" -eq 1 ] && ! "$py" -c 'import open3d' 2>/dev/null; then
  echo "odometry_benchmark: installing python3-open3d" >&2
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd=sudo
  $sudo_cmd apt-get install -y --no-install-recommends python3-open3d >&2
fi
for tool in synth run_bag evaluate; do
  if [ ! -x "$QS_WS/devel/lib/quadric_slam/$tool" ]; then
    echo "odometry_benchmark: building the workspace ($tool missing)" >&2
    qs_build >&2
    break
  fi
done

# Writes one result row (tab-separated) to $out/rows.tsv:
# sequence method ate rpe frames failures odo_median odo_p95 prep_median prep_p95 timing_note
rows="$out/rows.tsv"
: >"$rows"

evaluate_row() {  # sequence method trajectory timing.json kind(ours|open3d)
  local seq=$1 method=$2 traj=$3 timing=$4 kind=$5 eval_out
  eval_out=$("$QS_ROOT/scripts/evaluate" --gt "$out/$seq/groundtruth.txt" --est "$traj")
  echo "$eval_out" >"${traj%.txt}.eval.txt"
  local ate rpe pairs
  ate=$(awk '$1 == "ate_rmse_m" {print $2}' <<<"$eval_out")
  rpe=$(awk '$1 == "rpe_m_per_s" {print $2}' <<<"$eval_out")
  pairs=$(awk '$1 == "pairs" {print $2}' <<<"$eval_out")
  "$py" - "$timing" "$kind" "$seq" "$method" "$ate" "$rpe" "$pairs" >>"$rows" <<'EOF'
import json, sys
timing, kind, seq, method, ate, rpe, pairs = sys.argv[1:]
t = json.load(open(timing))
st = t["stages"]
def get(stage, key):
    return "%.2f" % st[stage][key] if stage in st else "-"
if kind == "ours":
    odo, prep, failures = "odometry", "normals", "-"
else:
    odo, prep, failures = "total", "prep", str(t.get("failures", "-"))
print("\t".join([seq, method, ate, rpe, str(t["frames"]), pairs, failures,
                 get(odo, "median_ms"), get(odo, "p95_ms"), get(prep, "median_ms"),
                 get(prep, "p95_ms")]))
EOF
}

load_before=$(uptime)
for seq in $sequences; do
  gt_file="$gt_dir/rgbd_dataset_${seq/fr/freiburg}-groundtruth.txt"
  [ -f "$gt_file" ] || { echo "odometry_benchmark: no ground truth $gt_file" >&2; exit 1; }
  dir="$out/$seq"
  if [ "$regenerate" -eq 1 ] || [ ! -f "$dir/depth.txt" ] || [ ! -f "$dir/groundtruth.txt" ]; then
    rm -rf "$dir"
    echo "== $seq: rendering $seconds s along $(basename "$gt_file")" >&2
    "$QS_ROOT/scripts/synth" --out "$dir" --trajectory "$gt_file" --seconds "$seconds" \
      --no-bag --no-labels --name "$seq" --threads "$QS_JOBS" >"$out/$seq.synth.log" 2>&1
  fi
  n=$(grep -vc '^#' "$dir/depth.txt")
  echo "== $seq: $n frames" >&2

  mkdir -p "$dir/ours"
  run_args=("$dir" --out "$dir/ours" --odometry-only --gt "$dir/groundtruth.txt")
  [ "$max_frames" -gt 0 ] && run_args+=(--max-frames "$max_frames")
  echo "== $seq: ours (scripts/run_bag --odometry-only)" >&2
  "$QS_ROOT/scripts/run_bag" "${run_args[@]}" >"$dir/ours/run_bag.log" 2>&1 ||
    { cat "$dir/ours/run_bag.log" >&2; exit 1; }
  evaluate_row "$seq" ours "$dir/ours/trajectory.txt" "$dir/ours/timing.json" ours

  [ "$open3d" -eq 1 ] || continue
  o3d_frames=$max_frames
  if [ "$o3d_max_frames" -gt 0 ] && { [ "$max_frames" -eq 0 ] || [ "$o3d_max_frames" -lt "$max_frames" ]; }; then
    o3d_frames=$o3d_max_frames
    echo "== $seq: ours on the first $o3d_frames frames (like for like with Open3D)" >&2
    mkdir -p "$dir/ours_first$o3d_frames"
    "$QS_ROOT/scripts/run_bag" "$dir" --out "$dir/ours_first$o3d_frames" --odometry-only \
      --max-frames "$o3d_frames" >"$dir/ours_first$o3d_frames/run_bag.log" 2>&1 ||
      { cat "$dir/ours_first$o3d_frames/run_bag.log" >&2; exit 1; }
    evaluate_row "$seq" "ours (first $o3d_frames frames)" "$dir/ours_first$o3d_frames/trajectory.txt" \
      "$dir/ours_first$o3d_frames/timing.json" ours
  fi
  for method in $methods; do
    echo "== $seq: open3d $method" >&2
    mkdir -p "$dir/open3d"
    # Direction check first: the chained motions must match groundtruth.txt, not its inverse.
    "$py" "$o3d_script" --seq "$dir" --method "$method" --out /dev/null --check-direction 10 \
      >"$dir/open3d/$method.check.log" 2>&1 || { cat "$dir/open3d/$method.check.log" >&2; exit 1; }
    tail -n 1 "$dir/open3d/$method.check.log" >&2
    o3d_args=(--seq "$dir" --method "$method" --out "$dir/open3d/$method.txt"
              --timing "$dir/open3d/$method.timing.json")
    [ "$o3d_frames" -gt 0 ] && o3d_args+=(--max-frames "$o3d_frames")
    "$py" "$o3d_script" "${o3d_args[@]}" >&2
    evaluate_row "$seq" "open3d $method" "$dir/open3d/$method.txt" \
      "$dir/open3d/$method.timing.json" open3d
  done
done
load_after=$(uptime)

"$py" - "$rows" "$out/odometry_benchmark.md" "$load_before" "$load_after" "$(nproc)" <<'EOF'
import sys
rows_path, md_path, before, after, cores = sys.argv[1:]
rows = [l.rstrip("\n").split("\t") for l in open(rows_path) if l.strip()]
lines = [
    "# Odometry benchmark (frame-to-frame / frame-to-keyframe, synthetic desk scene, real TUM motion)",
    "",
    "Machine: %s cores, shared. Load at start: `%s`. Load at end: `%s`." % (cores, before.strip(), after.strip()),
    "",
    "Timing: ours = the odometry stage of scripts/run_bag's timing.json (ICP against the keyframe; "
    "prep = the normals stage); Open3D = the whole per-frame cost from decoded images "
    "(prep = RGBD image / cloud + normals, then the odometry call), OMP_NUM_THREADS=1.",
    "",
    "| sequence | method | ATE RMSE (m) | RPE (m/s) | frames | ATE pairs | failed | median ms/frame | p95 ms/frame | prep median ms | prep p95 ms |",
    "|---|---|---|---|---|---|---|---|---|---|---|",
]
for r in rows:
    lines.append("| " + " | ".join(r) + " |")
text = "\n".join(lines) + "\n"
open(md_path, "w").write(text)
print(text)
EOF
echo "odometry_benchmark: table written to $out/odometry_benchmark.md" >&2
