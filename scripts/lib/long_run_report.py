"""Report of scripts/long_run: slopes of memory, time per frame and map size, and gnuplot plots.

Reads DIR/offline/resources.csv (run_bag) and DIR/live/{memory,diagnostics}.csv, writes
DIR/report.md, DIR/offline.png and DIR/live.png. Standard library only (Debian's python3).
"""
import argparse
import csv
import os
import statistics
import subprocess


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def slope_per_hour(xs_s, ys):
    """Least-squares slope of ys against xs (seconds), per hour; 0 for fewer than two points."""
    n = len(xs_s)
    if n < 2:
        return 0.0
    mx, my = sum(xs_s) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs_s)
    if sxx == 0:
        return 0.0
    return 3600.0 * sum((x - mx) * (y - my) for x, y in zip(xs_s, ys)) / sxx


def after_warm_up(rows, key="t"):
    """Rows after the first 10% of the run's duration."""
    if not rows:
        return rows
    t_end = rows[-1][key]
    return [r for r in rows if r[key] >= 0.1 * t_end]


def curve_line(name, unit, xs, ys):
    """One table row: after warm-up, at the end, slope per hour, median of first/last tenth."""
    if len(ys) < 2:
        return f"| {name} | {unit} | - | - | - | - | - |"
    tenth = max(1, len(ys) // 10)
    return "| {} | {} | {:.2f} | {:.2f} | {:+.3f} | {:.2f} | {:.2f} |".format(
        name, unit, ys[0], ys[-1], slope_per_hour(xs, ys), statistics.median(ys[:tenth]),
        statistics.median(ys[-tenth:]))


TABLE_HEAD = ("| curve | unit | after warm-up | at the end | slope per hour | median first tenth "
              "| median last tenth |\n|---|---|---|---|---|---|---|")


def gnuplot(script):
    subprocess.run(["gnuplot"], input=script, text=True, check=True)


def offline_section(out):
    rows = read_csv(os.path.join(out, "offline", "resources.csv"))
    if not rows:
        return "## Offline (run_bag)\nnot run\n"
    data = [{"t": float(r["elapsed_s"]), "frames": int(r["frames"]), "rss": float(r["rss_mb"]),
             "ms": float(r["ms_per_frame"]), "landmarks": int(r["landmarks"]),
             # (columns added later: absent in older files)
             "candidates": int(r.get("candidates") or 0),
             "points": int(r.get("reconstruction_points") or 0),
             "heap": float(r["heap_in_use_mb"]) if r.get("heap_in_use_mb") else None}
            for r in rows]
    warm = after_warm_up(data)
    xs = [r["t"] for r in warm]
    lines = ["## Offline (run_bag, frames rendered as needed)",
             f"{data[-1]['frames']} frames in {data[-1]['t'] / 60:.1f} min of wall time; "
             f"samples every 50 frames: {len(data)}; warm-up dropped: first 10% of the run.", "",
             TABLE_HEAD,
             curve_line("resident memory", "MB", xs, [r["rss"] for r in warm]),
             *([curve_line("heap in use (resident less what the allocator holds free)", "MB", xs,
                           [r["heap"] for r in warm])] if warm[0]["heap"] is not None else []),
             curve_line("time per frame (render + pipeline)", "ms", xs, [r["ms"] for r in warm]),
             curve_line("landmarks", "count", xs, [r["landmarks"] for r in warm]),
             curve_line("candidates (surfaces seen, not yet landmarks)", "count", xs,
                        [r["candidates"] for r in warm]),
             curve_line("reconstruction points", "count", xs, [r["points"] for r in warm]), "",
             f"landmarks: max {max(r['landmarks'] for r in data)} over the run; "
             f"memory: min {min(r['rss'] for r in data):.1f} MB, max "
             f"{max(r['rss'] for r in data):.1f} MB.", ""]
    csv_path = os.path.join(out, "offline", "resources.csv")
    png = os.path.join(out, "offline.png")
    # One panel per column of resources.csv (1-based gnuplot columns; column 3 is elapsed_s).
    panels = [("resident memory (MB)", 4, "RSS"),
              ("ms per frame", 5, "render + pipeline, mean of 50 frames"),
              ("landmarks", 6, "map landmarks"), ("candidates", 7, "candidates"),
              ("points", 8, "reconstruction points")]
    if "reconstruction_points" not in rows[0]:
        panels = panels[:3]
    if "heap_in_use_mb" in rows[0]:
        panels.insert(1, ("heap in use (MB)", 9, "resident less what the allocator holds free"))
    plots = "\n".join(f"set ylabel '{label}'\n"
                      f"plot '{csv_path}' every ::1 using ($3/60):{column} with lines lw 2 "
                      f"title '{title}'" for label, column, title in panels)
    gnuplot(f"""
set terminal png size 1000,{300 * len(panels)} noenhanced
set output '{png}'
set datafile separator ','
set multiplot layout {len(panels)},1 title 'run\\_bag on a generated sequence: resources over time'
set xlabel 'wall time (min)'
set grid
{plots}
unset multiplot
""")
    lines.append(f"plot: {png}\n")
    return "\n".join(lines)


def live_section(out):
    memory = read_csv(os.path.join(out, "live", "memory.csv"))
    diagnostics = read_csv(os.path.join(out, "live", "diagnostics.csv"))
    if not memory:
        return "## Live\nnot run\n"
    mem = [{"t": float(r["wall_s"]), "rss": float(r["rss_mb"])} for r in memory]
    warm = after_warm_up(mem)
    lines = ["## Live (quadric_slam.launch fed by synthetic_camera at real time)",
             f"duration {mem[-1]['t'] / 60:.1f} min; manager memory sampled every 10 s "
             f"({len(mem)} samples); warm-up dropped: first 10%.", "", TABLE_HEAD,
             curve_line("manager resident memory", "MB", [r["t"] for r in warm],
                        [r["rss"] for r in warm])]
    names = sorted({r["name"] for r in diagnostics})
    series_files = []
    for name in names:
        rows = [r for r in diagnostics if r["name"] == name and r["median_ms"]]
        pts = [{"t": float(r["wall_s"]), "median": float(r["median_ms"]),
                "processed": float(r["frames_processed"] or 0),
                "landmarks": float(r["landmarks"]) if r["landmarks"] else None,
                # (a column added later: absent in older files)
                "points": float(r["reconstruction_points"]) if r.get("reconstruction_points")
                else None,
                "heap": float(r["heap_in_use_mb"]) if r.get("heap_in_use_mb") else None}
               for r in rows]
        if not pts:
            continue
        warm_pts = after_warm_up(pts)
        short = name.split(":")[-1].strip() or name
        lines.append(curve_line(f"{short}: processing median (last 300 frames)", "ms",
                                [p["t"] for p in warm_pts], [p["median"] for p in warm_pts]))
        with_landmarks = [p for p in warm_pts if p["landmarks"] is not None]
        if with_landmarks:
            lines.append(curve_line(f"{short}: landmarks", "count",
                                    [p["t"] for p in with_landmarks],
                                    [p["landmarks"] for p in with_landmarks]))
        with_heap = [p for p in warm_pts if p["heap"] is not None]
        if with_heap:
            lines.append(curve_line("manager heap in use (resident less what the allocator "
                                    "holds free)", "MB", [p["t"] for p in with_heap],
                                    [p["heap"] for p in with_heap]))
            heap_series = os.path.join(out, "live", "series_heap.dat")
            with open(heap_series, "w") as f:  # comma-separated: plotted beside memory.csv
                for p in pts:
                    if p["heap"] is not None:
                        f.write(f"{p['t'] / 60:.3f},{p['heap']:.3f}\n")
        with_points = [p for p in warm_pts if p["points"] is not None]
        if with_points:
            lines.append(curve_line(f"{short}: reconstruction points", "count",
                                    [p["t"] for p in with_points],
                                    [p["points"] for p in with_points]))
        lines.append(f"| {short}: frames processed | count | - | {pts[-1]['processed']:.0f} | "
                     f"{3600 * pts[-1]['processed'] / max(pts[-1]['t'], 1):.0f} per hour | - | - |")
        path = os.path.join(out, "live", "series_" + "".join(c if c.isalnum() else "_" for c in short)
                            + ".dat")
        with open(path, "w") as f:
            for p in pts:
                f.write(f"{p['t'] / 60:.3f} {p['median']:.3f} "
                        f"{p['landmarks'] if p['landmarks'] is not None else 'NaN'}\n")
        series_files.append((short, path))
    png = os.path.join(out, "live.png")
    mem_csv = os.path.join(out, "live", "memory.csv")
    medians = ", ".join(f"'{p}' using 1:2 with lines title '{n}'" for n, p in series_files)
    landmark_plots = ", ".join(f"'{p}' using 1:3 with lines lw 2 title '{n}'"
                               for n, p in series_files if "mapping" in n)
    heap_series = os.path.join(out, "live", "series_heap.dat")
    heap_plot = (f", '{heap_series}' using 1:2 with lines lw 2 title 'heap in use'"
                 if os.path.exists(heap_series) else "")
    script = f"""
set terminal png size 1000,900 noenhanced
set output '{png}'
set datafile separator ','
set multiplot layout 3,1 title 'live pipeline at real time: resources over time'
set xlabel 'wall time (min)'
set grid
set ylabel 'manager RSS (MB)'
plot '{mem_csv}' every ::1 using ($1/60):2 with lines lw 2 title 'nodelet manager resident'{heap_plot}
set datafile separator whitespace
set ylabel 'processing median (ms)'
plot {medians if medians else "0 notitle"}
set ylabel 'landmarks'
plot {landmark_plots if landmark_plots else "0 notitle"}
unset multiplot
"""
    gnuplot(script)
    lines += ["", f"plot: {png}", ""]
    return "\n".join(lines)


def evaluation_section(out):
    """Each run's map and trajectory against the scene's truth (DIR/<part>/evaluation.txt, written
    by scripts/evaluate): ATE, the map summary, the per-class lines."""
    lines = ["## Maps against the scene's truth", ""]
    found = False
    for part in ("offline", "live"):
        path = os.path.join(out, part, "evaluation.txt")
        if not os.path.exists(path):
            continue
        found = True
        lines.append(f"{part} ({path}):")
        lines.append("")
        with open(path) as f:
            for line in f:
                if line.startswith(("ate_rmse_m", "pairs", "map_summary", "class ")):
                    lines.append("    " + line.rstrip())
        lines.append("")
    if not found:
        lines.append("(no evaluation: a run without its map, trajectory or ground truth)")
        lines.append("")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--header", default="# Long runs")
    args = parser.parse_args()
    report = "\n".join([args.header, "", offline_section(args.out), live_section(args.out),
                        evaluation_section(args.out)])
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write(report)


if __name__ == "__main__":
    main()
