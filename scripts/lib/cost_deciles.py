#!/usr/bin/env python3
"""Decile table of a run's cost (scripts/bounded_cost): run_bag's DIR/frames.csv (one line per frame)
and DIR/resources.csv (memory samples) split into ten equal parts of the run, in order. Per decile:
frames, keyframes, the window optimisation's median and p95 over its keyframes, the mapping stage's
median over all frames, the landmarks and window residuals at its end, the resident memory at its
end. The cost is bounded when the last decile's optimisation median is at most 1.5x the second's
(the first holds the start-up, when the window is still filling).

usage: cost_deciles.py DIR  (prints the table as markdown and writes DIR/deciles.md)"""
import csv
import os
import sys


def percentile(values, q):
    """Nearest-rank percentile, as eval/stage_timing.h; 0 for none."""
    if not values:
        return 0.0
    ordered = sorted(values)
    rank = max(1, int(-(-q * len(ordered) // 1)))  # ceil(q n), at least 1
    return ordered[min(rank, len(ordered)) - 1]


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "frames.csv")) as f:
        # A row cut short (a run still writing, or killed) is left out.
        frames = [r for r in csv.DictReader(f) if None not in r.values()]
    if len(frames) < 10:
        sys.exit(f"cost_deciles: {len(frames)} frames in {out}/frames.csv, need at least 10")
    memory = []
    resources = os.path.join(out, "resources.csv")
    if os.path.exists(resources):
        with open(resources) as f:
            memory = [(int(r["frames"]), float(r["rss_mb"])) for r in csv.DictReader(f)]

    def rss_at(frame):
        before = [mb for n, mb in memory if n <= frame]
        return before[-1] if before else float("nan")

    lines = ["| decile | frames | keyframes | optimisation median ms | optimisation p95 ms | "
             "mapping median ms (all frames) | landmarks at end | window residuals at end | "
             "resident MB at end |",
             "|---|---|---|---|---|---|---|---|---|"]
    medians = []
    n = len(frames)
    for d in range(10):
        part = frames[d * n // 10:(d + 1) * n // 10]
        key = [float(r["optimisation_ms"]) for r in part if r["keyframe"] == "1"]
        mapping = [float(r["mapping_ms"]) for r in part if float(r["mapping_ms"]) > 0]
        residuals = [int(r["window_residuals"]) for r in part if r["keyframe"] == "1"]
        medians.append(percentile(key, 0.5))
        lines.append(f"| {d + 1} | {len(part)} | {len(key)} | {percentile(key, 0.5):.2f} | "
                     f"{percentile(key, 0.95):.2f} | {percentile(mapping, 0.5):.2f} | "
                     f"{part[-1]['landmarks']} | {residuals[-1] if residuals else '-'} | "
                     f"{rss_at(int(part[-1]['frame'])):.1f} |")
    all_mapping = [float(r["mapping_ms"]) for r in frames if float(r["mapping_ms"]) > 0]
    ratio = medians[9] / medians[1] if medians[1] > 0 else float("inf")
    lines += ["",
              f"frames {n}; mapping median {percentile(all_mapping, 0.5):.2f} ms, p95 "
              f"{percentile(all_mapping, 0.95):.2f} ms per frame; resident memory "
              f"{memory[0][1] if memory else float('nan'):.1f} MB at frame "
              f"{memory[0][0] if memory else 0}, {memory[-1][1] if memory else float('nan'):.1f} MB "
              f"at frame {memory[-1][0] if memory else 0}",
              f"bounded: last decile's optimisation median / second's = {ratio:.2f} "
              f"({'<=' if ratio <= 1.5 else '>'} 1.5)"]
    table = "\n".join(lines) + "\n"
    with open(os.path.join(out, "deciles.md"), "w") as f:
        f.write(table)
    sys.stdout.write(table)


if __name__ == "__main__":
    main()
