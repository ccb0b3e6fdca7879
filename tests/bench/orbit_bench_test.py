#!/usr/bin/python3
"""bench/orbit_bench.py end to end with a small orbit: the scene file it writes, a row per
run of each binary with figures that add up, and clear errors for bad input.

    orbit_bench_test.py ORBIT_BENCH_PY OCTRAY
"""

import json
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

SCRIPT, OCTRAY = sys.argv[1], sys.argv[2]
ROW = re.compile(r"^([AB]) +(\d+) +([0-9.]+) +([0-9.]+) +([0-9.]+) +([0-9.]+) +([0-9.]+)$")


def orbit_bench(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True,
                          timeout=600)


class OrbitBenchTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(dir=os.environ.get("OCTRAY_TEST_TMPDIR"))
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_two_binaries_take_turns_and_each_run_is_a_row(self):
        done = orbit_bench(OCTRAY, OCTRAY, "--spheres", "2048", "--width", "96", "--height",
                           "64", "--frames", "3", "--runs", "2", "--dir", self.dir)
        self.assertEqual(done.returncode, 0, done.stderr)
        rows = [ROW.match(line) for line in done.stdout.splitlines()]
        rows = [m for m in rows if m]
        # A, B, A, B: the binaries alternate, run by run.
        self.assertEqual([(m.group(1), int(m.group(2))) for m in rows],
                         [("A", 1), ("B", 1), ("A", 2), ("B", 2)])
        for m in rows:
            wall, load, prepare, render, ratio = (float(m.group(i)) for i in range(3, 8))
            self.assertGreater(render, 0.001)
            self.assertLess(load + prepare + render, wall)
            # The ratio comes from the same figures, each printed to the millisecond.
            e = 0.0005
            low = (wall - load - 2 * e) / (render + e) - e
            high = (wall - load + 2 * e) / (render - e) + e
            self.assertTrue(low <= ratio <= high, (ratio, low, high))
        # A summary for each binary, of its own runs (the same file given twice included).
        summaries = [line for line in done.stdout.splitlines() if " median " in line]
        self.assertEqual(len(summaries), 2)
        for label, line in zip("AB", summaries):
            self.assertTrue(line.startswith(label + " = "), line)
            self.assertTrue(line.endswith(", 2 runs"), line)
        # Each frame's EXR is there, the last run's.
        frames = sorted(os.listdir(os.path.join(self.dir, "frames")))
        self.assertEqual(frames, ["o.0000.exr", "o.0001.exr", "o.0002.exr"])

    def test_the_scene_turns_the_eye_a_quarter_circle_about_the_look_at_point(self):
        done = orbit_bench(OCTRAY, "--spheres", "64", "--width", "32", "--height", "24",
                           "--frames", "5", "--runs", "1", "--dir", self.dir)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.dir, "orbit.json")) as f:
            scene = json.load(f)
        self.assertEqual(len(scene["objects"]), 64)
        animation = scene["animation"]
        self.assertEqual(animation["frames"], 5)
        keys = animation["camera"]
        self.assertEqual([k["frame"] for k in keys], [0, 1, 2, 3, 4])
        eye, lookat = scene["camera"]["eye"], scene["camera"]["lookat"]
        radius = math.hypot(eye[0] - lookat[0], eye[2] - lookat[2])
        for k in keys:
            e = k["eye"]
            self.assertAlmostEqual(math.hypot(e[0] - lookat[0], e[2] - lookat[2]), radius,
                                   places=4)
            self.assertAlmostEqual(e[1], eye[1], places=5)
        for a in range(3):
            self.assertAlmostEqual(keys[0]["eye"][a], eye[a], places=5)
        # The last key is a quarter turn from the first: perpendicular about the look-at.
        first = (eye[0] - lookat[0], eye[2] - lookat[2])
        last = (keys[-1]["eye"][0] - lookat[0], keys[-1]["eye"][2] - lookat[2])
        self.assertAlmostEqual(first[0] * last[0] + first[1] * last[1], 0.0, places=4)

    def test_bad_input_is_a_usage_error_or_a_named_failure(self):
        for args in (["--frames", "1"], ["--runs", "0"], ["--spheres", "0"]):
            done = orbit_bench(OCTRAY, *args)
            self.assertEqual(done.returncode, 2, args)
            self.assertIn("--frames must be 2 or more", done.stderr)
        missing = os.path.join(self.dir, "no-such-octray")
        done = orbit_bench(missing)
        self.assertEqual(done.returncode, 2)
        self.assertIn("is not an executable file", done.stderr)
        # An executable that is not octray: its `scene` command fails, and the message
        # says which command.
        done = orbit_bench("/bin/false", "--dir", self.dir)
        self.assertEqual(done.returncode, 1)
        self.assertIn("/bin/false scene random:1048576", done.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0]])
