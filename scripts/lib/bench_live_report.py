#!/usr/bin/python3
"""The live-rate benchmark's table (scripts/bench_live): for each nodelet the frames it processed
against the bag's depth frames, and its processing time from its final /diagnostics report; beside
it the offline runner's per-stage times on the same bag (run_bag's timing.json).

    bench_live_report.py --diagnostics D.yaml --bag BAG --depth-topic T --timing timing.json
                         --header TEXT --out report.md

Prints the report and writes it (Markdown) to --out. Exits 1 when a nodelet processed less than
--min-share (default 0.95) of the bag's frames or did not report.
"""
import argparse
import json
import os
import sys

import rosbag
import yaml

# Nodelet -> (its status on /diagnostics, the offline runner's stage(s) doing the same work).
# The front-end nodelets report as "quadric_slam: <nodelet name>" (ros/diagnostics.h), the mapper
# through its own updater as "<nodelet name>: mapping".
NODELETS = [
    ("normal_estimation", "quadric_slam: normal_estimation", ["normals"]),
    ("quadric_segmentation", "quadric_slam: quadric_segmentation", ["segmentation"]),
    ("odometry", "quadric_slam: odometry", ["odometry"]),
    ("mapping", "mapping: mapping", ["mapping", "reconstruction"]),
]


def number(values, key):
    try:
        return float(values[key])
    except (KeyError, ValueError):
        return None


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--diagnostics", required=True)
    parser.add_argument("--bag", required=True)
    parser.add_argument("--depth-topic", default="/camera/depth/image")
    parser.add_argument("--timing", required=True)
    parser.add_argument("--header", default="")
    parser.add_argument("--rate", type=float, default=1.0, help="the playback rate")
    parser.add_argument("--min-share", type=float, default=0.95)
    parser.add_argument("--live-cpu", help="'user system wall' seconds of the live launch")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()

    with rosbag.Bag(args.bag) as bag:
        bag_frames = bag.get_message_count(args.depth_topic)
        bag_seconds = bag.get_end_time() - bag.get_start_time()
    with open(args.diagnostics) as f:
        statuses = yaml.safe_load(f) or {}  # collect_diagnostics' file
    with open(args.timing) as f:
        timing = json.load(f)
    stages = timing.get("stages", {})

    lines = [args.header.rstrip("\n"), ""] if args.header else []
    lines.append("bag depth frames (%s): %d" % (args.depth_topic, bag_frames))
    lines.append("")
    lines.append("| nodelet | received | processed | dropped | share of bag frames | "
                 "live median ms | live p95 ms | offline median ms | offline p95 ms |")
    lines.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    failures = []
    for nodelet, status_name, offline_stages in NODELETS:
        status = statuses.get(status_name)
        values = status["values"] if status else {}
        processed = number(values, "frames processed")
        share = processed / bag_frames if processed is not None and bag_frames else None
        # The offline runner times each stage separately; a nodelet doing two is their sum.
        offline = [stages[s] for s in offline_stages if s in stages]
        offline_median = sum(s["median_ms"] for s in offline) if offline else None
        offline_p95 = sum(s["p95_ms"] for s in offline) if offline else None
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            nodelet, fmt(number(values, "frames received"), ".0f"), fmt(processed, ".0f"),
            fmt(number(values, "frames dropped"), ".0f"),
            "-" if share is None else "%.1f %%" % (100 * share),
            fmt(number(values, "processing time median (ms)"), ".1f"),
            fmt(number(values, "processing time p95 (ms)"), ".1f"),
            fmt(offline_median, ".1f"), fmt(offline_p95, ".1f")))
        if status is None:
            failures.append("%s: no /diagnostics status '%s'" % (nodelet, status_name))
        elif share is None or share < args.min_share:
            failures.append("%s processed %s of %d frames (< %.0f %%)" % (
                nodelet, fmt(processed, ".0f"), bag_frames, 100 * args.min_share))
    lines.append("")
    lines.append("(received = callbacks run; frames the subscriber queue overflowed never reach "
                 "one. Offline: scripts/run_bag, one thread, every frame; mapping offline = "
                 "mapping + reconstruction stages; sums of medians/p95s are approximate.)")
    offline_frames = timing.get("frames")
    if offline_frames is not None:
        lines.append("offline: %s frames in %.1f s wall" % (offline_frames,
                                                              timing.get("wall_s", 0.0)))
    # What keeping up costs: every stage's offline median per frame, at the played frame rate, in
    # cores (the stages run in parallel in the manager, but each frame needs all of them).
    per_frame_ms = sum(stages[s]["median_ms"] for _, _, names in NODELETS for s in names
                       if s in stages)
    if bag_seconds > 0 and per_frame_ms > 0:
        rate_hz = args.rate * bag_frames / bag_seconds
        lines.append("CPU to keep up: %.0f ms per frame (sum of the offline medians) x %.1f Hz "
                     "= %.2f cores busy (this machine: %d, shared)" % (
                         per_frame_ms, rate_hz, per_frame_ms * rate_hz / 1e3, os.cpu_count()))
    if args.live_cpu and os.path.exists(args.live_cpu):
        with open(args.live_cpu) as f:
            fields = f.read().split()
        if len(fields) >= 3 and float(fields[2]) > 0:
            user, system, wall = (float(v) for v in fields[:3])
            lines.append("live CPU: %.1f s user + %.1f s system over %.1f s wall = %.2f cores on "
                         "average (every process of the launch: player, manager, helpers; %d "
                         "cores here, shared)" % (user, system, wall, (user + system) / wall,
                                                  os.cpu_count()))
    lines.append("")
    lines.append("result: " + ("PASS (every nodelet >= %.0f %% of the bag's frames)" %
                               (100 * args.min_share) if not failures else
                               "FAIL: " + "; ".join(failures)))
    text = "\n".join(lines) + "\n"
    with open(args.out, "w") as out:
        out.write(text)
    sys.stdout.write(text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
