#!/usr/bin/env python3
"""A camera orbit rendered to EXR files, timed as a user runs it: issue 41's whole-command
figure for an animation whose scene is prepared once.

    orbit_bench.py OCTRAY [OTHER_OCTRAY] [--spheres N] [--width W] [--height H]
                   [--frames F] [--threads T] [--runs R] [--dir DIR]

Writes random:N (default 1048576 spheres, 1920x1080) as a JSON file with F camera keys
(default 12) turning the eye a quarter circle about the look-at point, then runs
`OCTRAY render orbit.json -o o.####.exr --threads T --stats` R times (default 3) and prints,
for each run, the process's wall time, the scene load (its `--stats` line), frame 0's
prepare (compile + BVH), the sum of the frames' render times (each EXR's
renderTimeSeconds, in full) and

    (wall - load) / sum render

what the command costs beyond its renders once the scene is read (1.00: nothing but
the renders). With OTHER_OCTRAY the two binaries take turns, run by run, so that both
see the same minutes of a shared machine; the summary gives each one's median. A bench,
not a test: it asserts nothing about speed. Exit 1 if a render fails or prints no
`--stats` lines, 2 on a usage error. The JSON (about 114 MB for a million spheres) is
written once into DIR (default: a temporary directory, removed at the end).
"""

import argparse
import math
import os
import re
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time

STATS = re.compile(r"stats: .* frame (\d+): load ([0-9.]+) s, compile ([0-9.]+) s, "
                   r"BVH ([0-9.]+) s, render ([0-9.]+) s")


def fail(message):
    print("orbit_bench.py: " + message, file=sys.stderr)
    sys.exit(1)


def write_orbit(octray, spec, frames, path):
    """The scene as JSON with an animation of `frames` camera keys: the eye turned about
    the look-at point's vertical axis by 0 ... 90 degrees."""
    made = subprocess.run([octray, "scene", spec], capture_output=True, text=True)
    if made.returncode != 0:
        fail(f"{octray} scene {spec} failed ({made.returncode}): {made.stderr.strip()}")
    text = made.stdout.rstrip()
    camera = re.search(r'"camera":\s*\{[^}]*\}', text)
    eye = camera and re.search(r'"eye":\s*\[([^\]]*)\]', camera.group(0))
    lookat = camera and re.search(r'"lookat":\s*\[([^\]]*)\]', camera.group(0))
    if not (text.endswith("}") and eye and lookat):
        fail(f"{octray} scene {spec} wrote no JSON object with a camera's eye and lookat")
    e = [float(v) for v in eye.group(1).split(",")]
    c = [float(v) for v in lookat.group(1).split(",")]
    dx, dz = e[0] - c[0], e[2] - c[2]
    keys = []
    for k in range(frames):
        a = (math.pi / 2) * k / (frames - 1)
        x = c[0] + dx * math.cos(a) + dz * math.sin(a)
        z = c[2] - dx * math.sin(a) + dz * math.cos(a)
        keys.append(f'{{"frame": {k}, "eye": [{x:.6f}, {e[1]:.6f}, {z:.6f}]}}')
    animation = (f',\n"animation": {{"frames": {frames}, "fps": 24, "camera": ['
                 + ", ".join(keys) + "]}\n}\n")
    with open(path, "w") as f:
        f.write(text[:-1].rstrip() + animation)


def render_time(exr_path):
    """The frame's renderTimeSeconds attribute (a double) from its EXR header."""
    with open(exr_path, "rb") as f:
        head = f.read(1 << 16)
    at = head.find(b"renderTimeSeconds\x00double\x00")
    if at < 0:
        fail(f"{exr_path} has no renderTimeSeconds attribute")
    at += len(b"renderTimeSeconds\x00double\x00")
    size, value = struct.unpack("<id", head[at:at + 12])
    if size != 8:
        fail(f"{exr_path}: renderTimeSeconds is {size} bytes, expected a double")
    return value


def run_once(octray, scene, frames, threads, out_dir):
    for name in os.listdir(out_dir):
        os.remove(os.path.join(out_dir, name))
    command = [octray, "render", scene, "-o", os.path.join(out_dir, "o.####.exr"),
               "--threads", str(threads), "--stats"]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
    wall = time.monotonic() - start
    if done.returncode != 0:
        fail(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip()}")
    stats = {int(m.group(1)): m for m in STATS.finditer(done.stderr)}
    if 0 not in stats:
        fail(f"{' '.join(command)} printed no --stats line for frame 0")
    load = float(stats[0].group(2))
    prepare = float(stats[0].group(3)) + float(stats[0].group(4))
    renders = [render_time(os.path.join(out_dir, f"o.{k:04d}.exr")) for k in range(frames)]
    total = sum(renders)
    ratio = (wall - load) / total if total > 0 else float("nan")
    return {"wall": wall, "load": load, "prepare": prepare, "render": total, "ratio": ratio}


def main():
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("octray", help="the octray executable")
    parser.add_argument("other", nargs="?", help="a second octray executable, run in turns")
    parser.add_argument("--spheres", type=int, default=1048576)
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--frames", type=int, default=12, help="camera keys, 2 or more")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--runs", type=int, default=3, help="runs of each binary")
    parser.add_argument("--dir", help="where the scene and frames go (kept)")
    args = parser.parse_args()
    if args.frames < 2 or args.runs < 1 or args.spheres < 1 or args.threads < 1:
        parser.error("--frames must be 2 or more; --runs, --spheres and --threads 1 or more")
    binaries = [args.octray] + ([args.other] if args.other else [])
    for b in binaries:
        if not (os.path.isfile(b) and os.access(b, os.X_OK)):
            parser.error(f"{b} is not an executable file")

    work = args.dir or tempfile.mkdtemp(prefix="orbit_bench.")
    os.makedirs(work, exist_ok=True)
    try:
        scene = os.path.join(work, "orbit.json")
        spec = f"random:{args.spheres},width={args.width},height={args.height}"
        write_orbit(args.octray, spec, args.frames, scene)
        out_dir = os.path.join(work, "frames")
        os.makedirs(out_dir, exist_ok=True)
        print(f"{spec}, {args.frames} camera keys, --threads {args.threads}: "
              f"{os.path.getsize(scene) / 1e6:.1f} MB of JSON")
        print(f"{'binary':8} {'run':>3} {'wall s':>8} {'load s':>8} {'prepare s':>9} "
              f"{'render s':>9}  (wall - load) / sum render")
        # Each binary's ratios, by its place on the command line (the two may be one file).
        ratios = [[] for _ in binaries]
        for run in range(1, args.runs + 1):
            for k, (label, b) in enumerate(zip("AB", binaries)):
                r = run_once(b, scene, args.frames, args.threads, out_dir)
                ratios[k].append(r["ratio"])
                print(f"{label:8} {run:>3} {r['wall']:8.3f} {r['load']:8.3f} "
                      f"{r['prepare']:9.3f} {r['render']:9.3f}  {r['ratio']:.3f}", flush=True)
        for label, b, mine in zip("AB", binaries, ratios):
            print(f"{label} = {b}: (wall - load) / sum render median "
                  f"{statistics.median(mine):.3f} (min {min(mine):.3f}, "
                  f"max {max(mine):.3f}), {len(mine)} runs")
    finally:
        if not args.dir:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
