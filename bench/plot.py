#!/usr/bin/python3
"""Charts of `octray bench --json` reports, to read at a glance.

    bench/plot.py run.json [more.json ...] [-o DIR] [--format png,svg]

Writes into DIR (default: the current directory), each as PNG and SVG unless --format
says otherwise:

  mrays.{png,svg}    Mrays/s, a panel per ray kind, scenes side by side, octray against
                     Embree (each system's best valid row at the largest thread count, a
                     min-max bar over its repetitions, octray / Embree above the pair: a
                     loss in red, a row whose repetitions spread too far marked "~"); the
                     subtitle says where and how it was measured
  scaling.{png,svg}  Mrays/s against threads, one panel per ray kind (only when the rows
                     hold more than one thread count: `octray bench --threads 1,2,4`)
  isa.{png,svg}      octray's Mrays/s by instruction set (only when the rows hold more than
                     one: `octray bench --isa sse2,sse4.1,avx2`)

Several files are pooled as if they were one run (a run per thread count, say); a
configuration measured in more than one of them is shown at its best. Invalid rows (their
validation failed, so their speed means nothing) are left out and counted on stderr.

Needs matplotlib: Debian's python3-matplotlib, for Debian's /usr/bin/python3. Exit
status: 0 charts written, 1 an input file is missing or not a bench report (the message
names the file, the row and the key), 2 a usage error.
"""

import argparse
import json
import math
import os
import sys

FORMATS = ("png", "svg")
RAY_KINDS = ("primary", "shadow", "secondary", "still", "frame", "whitted")
# What each ray kind's panel is called ("whitted": whole frames in reports before there
# were two kinds of them).
KIND_TITLES = {
    "primary": "primary rays",
    "shadow": "shadow rays",
    "secondary": "mirror rays",
    "still": "whole frame: scene made ready + first frame",
    "frame": "whole frame of a scene made ready before",
    "whitted": "whole frame",
}
KIND_SHORT = {"secondary": "mirror", "whitted": "whole frame"}
LOSS_COLOR = "#C00000"
# Colors that read apart in print and for the common color-vision deficiencies.
OCTRAY_COLOR = "#0072B2"
EMBREE_COLOR = "#E69F00"
ISA_COLORS = ("#56B4E9", "#009E73", "#0072B2", "#CC79A7", "#D55E00")

# A row's keys that the charts read, with their JSON types.
ROW_KEYS = {
    "scene": str,
    "ray_kind": str,
    "system": str,
    "mode": str,
    "isa": str,
    "threads": int,
    "mrays_median": (int, float),
    "valid": bool,
}


class InputError(Exception):
    """A file that is not a bench report; the message names the file and what is wrong."""


def load_report(path):
    """(rows, context) of one `octray bench --json` file, the rows checked for the keys the
    charts use."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}") from None
    try:
        report = json.loads(text)
    except json.JSONDecodeError as e:
        raise InputError(
            f"{path}: line {e.lineno}, column {e.colno}: not valid JSON: {e.msg}") from None
    if not isinstance(report, dict) or not isinstance(report.get("rows"), list):
        raise InputError(f"{path}: expected an object with a \"rows\" array, as "
                         "`octray bench --json` writes")
    rows = []
    for i, row in enumerate(report["rows"]):
        if not isinstance(row, dict):
            raise InputError(f"{path}: rows[{i}]: expected an object")
        for key, kind in ROW_KEYS.items():
            if key not in row:
                raise InputError(f"{path}: rows[{i}]: missing key \"{key}\"")
            value = row[key]
            # JSON true is not a number of threads, nor 1.5 one.
            if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool)):
                raise InputError(f"{path}: rows[{i}].{key}: expected "
                                 f"{type_name(kind)}, found {json.dumps(value)}")
        if not math.isfinite(row["mrays_median"]) or row["mrays_median"] < 0:
            raise InputError(f"{path}: rows[{i}].mrays_median: expected a number >= 0, "
                             f"found {row['mrays_median']}")
        rows.append(row)
    context = report.get("context")
    return rows, context if isinstance(context, dict) else {}


def type_name(kind):
    if kind is str:
        return "a string"
    if kind is bool:
        return "true or false"
    if kind is int:
        return "an integer"
    return "a number"


def best(rows, key):
    """{key(row): the row with the highest Mrays/s} over `rows`."""
    out = {}
    for row in rows:
        k = key(row)
        if k not in out or row["mrays_median"] > out[k]["mrays_median"]:
            out[k] = row
    return out


def ordered(values, order=()):
    """`values` once each: those in `order` first, in its order, then the others as met."""
    seen = list(dict.fromkeys(values))
    return [v for v in order if v in seen] + [v for v in seen if v not in order]


def groups_of(rows):
    """(scene, ray kind) pairs in the order of the report: scenes as met, kinds as run."""
    scenes = ordered(r["scene"] for r in rows)
    kinds = ordered((r["ray_kind"] for r in rows), RAY_KINDS)
    present = {(r["scene"], r["ray_kind"]) for r in rows}
    return [(s, k) for s in scenes for k in kinds if (s, k) in present]


def use_log_scale(axis, values):
    positive = [v for v in values if v > 0]
    if positive and max(positive) / min(positive) > 30:
        axis.set_yscale("log")


def subtitle(context, threads):
    """Where and how a report was measured, in one line: CPU, ISA, size, threads, reps,
    date, load."""
    parts = []
    if context.get("cpu"):
        cpus = context.get("logical_cpus")
        parts.append(f"{context['cpu']}" + (f" ({cpus} logical)" if cpus else ""))
    if context.get("isa"):
        parts.append(f"octray {context['isa']}")
    if context.get("width") and context.get("height"):
        parts.append(f"{context['width']}×{context['height']}")
    parts.append(f"{threads} thread{'s' if threads != 1 else ''}")
    if context.get("reps"):
        reps = f"{context['reps']} reps"
        if context.get("min_time"):
            reps += f" ≥ {context['min_time']:g} s each"
        parts.append(reps)
    if context.get("date"):
        parts.append(str(context["date"]).replace("T", " ").replace("Z", " UTC"))
    if "load_average" in context:
        parts.append(f"load {context['load_average']:.2f}")
    return " · ".join(parts)


def spread_of(row):
    """(below, above) the median for a min-max bar, or None without the figures."""
    lo, hi = row.get("mrays_min"), row.get("mrays_max")
    if not isinstance(lo, (int, float)) or not isinstance(hi, (int, float)):
        return None
    mid = row["mrays_median"]
    return max(0.0, mid - lo), max(0.0, hi - mid)


def mrays_chart(plt, rows, context=None):
    """A panel per ray kind: octray's and Embree's best Mrays/s per scene, min-max bars,
    octray / Embree above each pair (losses in red)."""
    context = context or {}
    threads = max(r["threads"] for r in rows)
    at = [r for r in rows if r["threads"] == threads]
    top = best(at, lambda r: (r["scene"], r["ray_kind"], r["system"]))
    scenes = ordered(r["scene"] for r in at)
    kinds = ordered((r["ray_kind"] for r in at), RAY_KINDS)
    systems = [s for s in ("octray", "embree") if any(k[2] == s for k in top)]
    columns = 1 if len(kinds) == 1 else 2 if len(kinds) <= 4 else 3
    panel_rows = math.ceil(len(kinds) / columns)
    panel_width = max(3.6, 0.95 * len(scenes) + 1.2)
    fig, axes = plt.subplots(panel_rows, columns,
                             figsize=(panel_width * columns, 2.9 * panel_rows + 1.1),
                             squeeze=False)
    width = 0.8 / len(systems)
    # Scene names side by side at 7.5 pt take about 0.06 in a character: turned when the
    # longest would reach its neighbours.
    pitch = (panel_width - 1.2) / max(1, len(scenes))
    rotate = max(len(s) for s in scenes) * 0.06 > 0.85 * pitch
    losses = 0
    for index, kind in enumerate(kinds):
        axis = axes[index // columns][index % columns]
        values = []
        for n, system in enumerate(systems):
            xs, ys, errors = [], [], [[], []]
            for g, scene in enumerate(scenes):
                row = top.get((scene, kind, system))
                if not row:
                    continue
                xs.append(g + (n - (len(systems) - 1) / 2) * width)
                ys.append(row["mrays_median"])
                spread = spread_of(row) or (0.0, 0.0)
                errors[0].append(spread[0])
                errors[1].append(spread[1])
                values += [row["mrays_median"] - spread[0], row["mrays_median"] + spread[1]]
            color = OCTRAY_COLOR if system == "octray" else EMBREE_COLOR
            name = "octray" if system == "octray" else "Embree 3 (best configuration)"
            axis.bar(xs, ys, width, label=name, color=color, yerr=errors,
                     error_kw={"elinewidth": 0.8, "capsize": 2, "ecolor": "#333333"})
        if len(systems) == 2:
            for g, scene in enumerate(scenes):
                o, e = top.get((scene, kind, "octray")), top.get((scene, kind, "embree"))
                if not (o and e and e["mrays_median"] > 0):
                    continue
                ratio = o["mrays_median"] / e["mrays_median"]
                loss = ratio < 1.0
                losses += loss
                unsteady = o.get("steady") is False or e.get("steady") is False
                text = f"{ratio:.2f}×" + ("~" if unsteady else "") + (" loss" if loss else "")
                peak = max(o["mrays_median"] + (spread_of(o) or (0, 0))[1],
                           e["mrays_median"] + (spread_of(e) or (0, 0))[1])
                axis.annotate(text, (g, peak), xytext=(0, 3), textcoords="offset points",
                              ha="center", va="bottom", fontsize=7,
                              color=LOSS_COLOR if loss else "black",
                              fontweight="bold" if loss else "normal")
        axis.set_title(KIND_TITLES.get(kind, kind), fontsize=9)
        axis.set_xticks(range(len(scenes)))
        axis.set_xticklabels(scenes, fontsize=7.5, rotation=20 if rotate else 0,
                             ha="right" if rotate else "center")
        axis.set_xlim(-0.6, len(scenes) - 0.4)
        use_log_scale(axis, [v for v in values if v > 0])
        if axis.get_yscale() == "linear":
            axis.set_ylim(0, max(values or [1]) * 1.18)
        else:
            axis.set_ylim(top=max(values or [1]) * 2.0)
        axis.grid(axis="y", alpha=0.3)
        axis.tick_params(axis="y", labelsize=7)
        if index % columns == 0:
            axis.set_ylabel("Mrays/s", fontsize=8)
    for index in range(len(kinds), panel_rows * columns):
        axes[index // columns][index % columns].axis("off")
    handles, labels = axes[0][0].get_legend_handles_labels()
    title = "Rays per second: octray against Embree"
    if len(systems) == 1:
        title = "Rays per second: octray"
    fig.suptitle(title, fontsize=11, y=0.995)
    fig.text(0.5, 1.0 - 0.36 / fig.get_figheight(), subtitle(context, threads), ha="center",
             va="top", fontsize=7.5, color="#444444")
    note = "bars: median of the repetitions, whiskers: min to max"
    if len(systems) == 2:
        note += ("; above each pair: octray / Embree" + ("\n" if fig.get_figwidth() < 9 else
                                                         " ") +
                 "(red: a loss; ~: a row's repetitions spread past the bound)")
    # The legend, then the note below it: their own strip under the panels.
    bottom = (0.75 if "\n" in note else 0.6) / fig.get_figheight()
    fig.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, bottom - 0.3 /
                                                                  fig.get_figheight()),
               fontsize=7.5, ncol=2, frameon=False)
    fig.text(0.01, 0.01, note, ha="left", va="bottom", fontsize=6.5, color="#444444")
    fig.tight_layout(rect=(0, bottom, 1, 1.0 - 0.45 / fig.get_figheight()))
    return fig


def scaling_chart(plt, rows):
    """Mrays/s against threads: a panel per ray kind, a line per scene and system."""
    kinds = ordered((r["ray_kind"] for r in rows), RAY_KINDS)
    scenes = ordered(r["scene"] for r in rows)
    top = best(rows, lambda r: (r["scene"], r["ray_kind"], r["system"], r["threads"]))
    counts = sorted({r["threads"] for r in rows})
    fig, axes = plt.subplots(1, len(kinds), figsize=(3.6 * len(kinds) + 1, 3.8),
                             squeeze=False)
    markers = "osD^vP*X"
    for axis, kind in zip(axes[0], kinds):
        values = []
        for n, scene in enumerate(scenes):
            for system in ("octray", "embree"):
                points = [(t, top[(scene, kind, system, t)]["mrays_median"])
                          for t in counts if (scene, kind, system, t) in top]
                if not points:
                    continue
                values += [p[1] for p in points]
                axis.plot([p[0] for p in points], [p[1] for p in points],
                          marker=markers[n % len(markers)],
                          linestyle="-" if system == "octray" else "--",
                          color=OCTRAY_COLOR if system == "octray" else EMBREE_COLOR,
                          label=f"{scene} {'octray' if system == 'octray' else 'Embree'}")
        axis.set_title(kind)
        axis.set_xlabel("threads")
        if counts[-1] >= 4 * counts[0]:
            axis.set_xscale("log", base=2)
        axis.set_xticks(counts)
        axis.set_xticklabels([str(c) for c in counts])
        use_log_scale(axis, values)
        axis.grid(alpha=0.3)
    axes[0][0].set_ylabel("Mrays/s")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(4, max(1, len(labels))),
               fontsize=7)
    fig.suptitle("Thread scaling (octray solid, Embree dashed)")
    fig.tight_layout(rect=(0, 0.06 + 0.04 * (len(labels) // 4), 1, 1))
    return fig


def isa_chart(plt, rows):
    """octray's best Mrays/s per ISA, grouped by scene and ray kind."""
    octray = [r for r in rows if r["system"] == "octray"]
    threads = max(r["threads"] for r in octray)
    at = [r for r in octray if r["threads"] == threads]
    top = best(at, lambda r: (r["scene"], r["ray_kind"], r["isa"]))
    isas = ordered((r["isa"] for r in at), ("scalar", "sse2", "sse4.1", "avx2", "avx512"))
    groups = groups_of(at)
    fig, axis = plt.subplots(figsize=(max(6.0, 0.9 * len(groups) + 2), 4.2))
    width = 0.8 / len(isas)
    values = []
    for n, isa in enumerate(isas):
        xs, ys = [], []
        for g, (scene, kind) in enumerate(groups):
            row = top.get((scene, kind, isa))
            if row:
                xs.append(g + (n - (len(isas) - 1) / 2) * width)
                ys.append(row["mrays_median"])
        axis.bar(xs, ys, width, label=isa, color=ISA_COLORS[n % len(ISA_COLORS)])
        values += ys
    axis.set_xticks(range(len(groups)))
    axis.set_xticklabels([f"{s}\n{KIND_SHORT.get(k, k)}" for s, k in groups], fontsize=8)
    axis.set_ylabel("Mrays/s")
    use_log_scale(axis, values)
    axis.set_title(f"octray by instruction set, {threads} thread{'s' if threads != 1 else ''}")
    axis.legend(fontsize=8, title="ISA", title_fontsize=8)
    axis.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def parse_formats(text):
    formats = [f.strip().lower() for f in text.split(",") if f.strip()]
    for f in formats:
        if f not in FORMATS:
            raise argparse.ArgumentTypeError(
                f"unknown format \"{f}\"; expected a comma-separated list of "
                f"{', '.join(FORMATS)}")
    if not formats:
        raise argparse.ArgumentTypeError("expected png, svg or png,svg")
    return list(dict.fromkeys(formats))


def main(argv):
    parser = argparse.ArgumentParser(
        prog="plot.py",
        description="Charts of `octray bench --json` reports: Mrays/s of octray and "
        "Embree by scene and ray kind, thread scaling, ISA comparison.",
        epilog="Example: octray bench whitted random:1024 --threads 1,2 --json run.json && "
        "bench/plot.py run.json -o charts")
    parser.add_argument("files", nargs="+", metavar="FILE.json",
                        help="reports written by `octray bench --json`, pooled")
    parser.add_argument("-o", "--output-dir", default=".", metavar="DIR",
                        help="directory for the charts, created if missing [default: .]")
    parser.add_argument("--format", type=parse_formats, default=list(FORMATS),
                        metavar="LIST", help="png, svg or png,svg [default: png,svg]")
    args = parser.parse_args(argv)

    try:
        rows, contexts = [], []
        for path in args.files:
            file_rows, context = load_report(path)
            rows += file_rows
            contexts.append(context)
    except InputError as e:
        print(f"plot.py: error: {e}", file=sys.stderr)
        return 1
    valid = [r for r in rows if r["valid"]]
    if len(valid) < len(rows):
        print(f"plot.py: left out {len(rows) - len(valid)} invalid rows (failed validation)",
              file=sys.stderr)
    if not valid:
        print(f"plot.py: error: {', '.join(args.files)}: no valid rows to plot",
              file=sys.stderr)
        return 1

    try:
        import matplotlib
    except ImportError:
        print("plot.py: error: needs matplotlib: Debian's python3-matplotlib, run with "
              "/usr/bin/python3 (tools/setup.sh installs it)", file=sys.stderr)
        return 1
    matplotlib.use("Agg")  # files only: no display needed
    matplotlib.rcParams["svg.hashsalt"] = "octray"  # the same SVG for the same data
    matplotlib.rcParams["svg.fonttype"] = "none"  # text stays text: searchable, smaller
    import matplotlib.pyplot as plt

    charts = [("mrays", mrays_chart(plt, valid, contexts[0]))]
    if len({r["threads"] for r in valid}) > 1:
        charts.append(("scaling", scaling_chart(plt, valid)))
    if len({r["isa"] for r in valid if r["system"] == "octray"}) > 1:
        charts.append(("isa", isa_chart(plt, valid)))

    try:
        os.makedirs(args.output_dir, exist_ok=True)
    except OSError as e:
        print(f"plot.py: error: cannot create {args.output_dir}: {e.strerror}",
              file=sys.stderr)
        return 1
    for name, fig in charts:
        for fmt in args.format:
            path = os.path.join(args.output_dir, f"{name}.{fmt}")
            # Written under a temporary name and renamed: a chart is complete or absent.
            tmp = os.path.join(args.output_dir, f".{name}.tmp.{os.getpid()}.{fmt}")
            try:
                fig.savefig(tmp, format=fmt, dpi=120,
                            metadata={"Date": None} if fmt == "svg" else None)
                os.replace(tmp, path)
            except OSError as e:
                if os.path.exists(tmp):
                    os.remove(tmp)
                print(f"plot.py: error: cannot write {path}: {e.strerror}", file=sys.stderr)
                return 1
            print(f"wrote {path}")
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
