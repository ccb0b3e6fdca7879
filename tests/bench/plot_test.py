#!/usr/bin/python3
"""bench/plot.py end to end: charts from a real (trimmed) `octray bench --json` report.

    plot_test.py PLOT_PY FIXTURE_JSON

Checks that the charts are written as valid PNG and SVG, that the charts a report calls for
are the ones made (thread scaling only with several thread counts, the ISA chart only with
several ISAs), and that bad input is a clear error with a non-zero status.
"""

import json
import os
import struct
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

PLOT, FIXTURE = sys.argv[1], sys.argv[2]


def plot(*args):
    return subprocess.run([sys.executable, PLOT, *args], capture_output=True, text=True,
                          timeout=120)


def load_plot_module():
    """bench/plot.py as a module, to look at its figures before they are files."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("octray_plot", PLOT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    import matplotlib
    matplotlib.use("Agg")
    return module


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise AssertionError(f"{path} is not a PNG")
    return struct.unpack(">II", head[16:24])


class PlotTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def write_json(self, name, report):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            json.dump(report, f)
        return path

    def fixture(self):
        with open(FIXTURE) as f:
            return json.load(f)

    def test_every_chart_as_png_and_svg(self):
        out = os.path.join(self.dir, "charts")  # created by plot.py
        r = plot(FIXTURE, "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        # The fixture has two thread counts and two ISAs: all three charts.
        self.assertEqual(sorted(os.listdir(out)),
                         ["isa.png", "isa.svg", "mrays.png", "mrays.svg", "scaling.png",
                          "scaling.svg"])
        for name in ("mrays", "scaling", "isa"):
            width, height = png_size(os.path.join(out, name + ".png"))
            self.assertGreater(width, 300)
            self.assertGreater(height, 200)
            root = ET.parse(os.path.join(out, name + ".svg")).getroot()
            self.assertEqual(root.tag, "{http://www.w3.org/2000/svg}svg")
            self.assertIn(f"wrote {os.path.join(out, name + '.png')}", r.stdout)
        # Text stays text in the SVG: the scenes, ray kinds and systems are labelled.
        with open(os.path.join(out, "mrays.svg")) as f:
            svg = f.read()
        for word in ("whitted", "random:64", "primary", "shadow", "octray", "Embree"):
            self.assertIn(word, svg)
        with open(os.path.join(out, "isa.svg")) as f:
            svg = f.read()
        for word in ("sse2", "avx2"):
            self.assertIn(word, svg)

    # Issue 42: a chart readable at a glance: a panel per ray kind (titled by what it
    # measures, not "whitted whitted"), scene labels that do not overlap, a subtitle that
    # says where and how it was measured, min-max bars, losses marked.
    def synthetic_report(self):
        """Five long scene names, every ray kind, one loss, one unsteady row."""
        report = self.fixture()
        template = next(r for r in report["rows"] if r["system"] == "octray")
        rows = []
        scenes = ["whitted", "random:1024", "random:65536", "random:1048576", "sphereflake:5"]
        for n, scene in enumerate(scenes):
            for kind in ("primary", "shadow", "secondary", "still", "frame"):
                for system, rate in (("octray", 100.0 + n), ("embree", 50.0 + n)):
                    if scene == "random:65536" and kind == "secondary" and system == "embree":
                        rate = 150.0  # a loss
                    row = dict(template, scene=scene, ray_kind=kind, system=system,
                               threads=2, mrays_median=rate, mrays_min=0.9 * rate,
                               mrays_max=1.1 * rate, valid=True,
                               steady=not (scene == "whitted" and kind == "primary"))
                    rows.append(row)
        report["rows"] = rows
        return report

    def test_panels_labels_subtitle_spread_and_losses(self):
        plot_module = load_plot_module()
        import matplotlib.pyplot as plt
        report = self.synthetic_report()
        fig = plot_module.mrays_chart(plt, report["rows"], report["context"])
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        panels = [a for a in fig.axes if a.axison]
        self.assertEqual(len(panels), 5)
        titles = [a.get_title() for a in panels]
        self.assertEqual(titles, [plot_module.KIND_TITLES[k] for k in
                                  ("primary", "shadow", "secondary", "still", "frame")])
        for axis in panels:
            labels = [t for t in axis.get_xticklabels() if t.get_text()]
            self.assertEqual([t.get_text() for t in labels][:2], ["whitted", "random:1024"])
            boxes = [t.get_window_extent(renderer) for t in labels]
            for a, b in zip(boxes, boxes[1:]):
                self.assertFalse(a.overlaps(b), f"{axis.get_title()}: scene labels overlap")
            # Every bar pair has its min-max whiskers.
            bars = [c for c in axis.containers if hasattr(c, "errorbar")]
            self.assertEqual(len(bars), 2)
            for c in bars:
                self.assertIsNotNone(c.errorbar)
        texts = [t.get_text() for t in fig.texts]
        context = report["context"]
        subtitle = next(t for t in texts if context["cpu"] in t)
        for part in (context["isa"], f"{context['width']}×{context['height']}", "2 threads",
                     f"{context['reps']} reps", context["date"][:10]):
            self.assertIn(part, subtitle)
        annotations = [c.get_text() for a in panels for c in a.texts]
        losses = [t for t in annotations if t.endswith("loss")]
        self.assertEqual(losses, ["0.68× loss"])  # 102 / 150
        self.assertTrue(any(t.endswith("×~") for t in annotations), annotations)
        plt.close(fig)

    def test_format_and_only_the_charts_the_data_calls_for(self):
        report = self.fixture()
        report["rows"] = [r for r in report["rows"]
                          if r["threads"] == 2 and r["isa"] in ("avx2", "user")]
        path = self.write_json("one.json", report)
        r = plot(path, "-o", self.dir, "--format", "svg")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.dir, "mrays.svg")))
        for name in ("mrays.png", "scaling.svg", "isa.svg"):
            self.assertFalse(os.path.exists(os.path.join(self.dir, name)), name)

    def test_several_files_are_pooled(self):
        report = self.fixture()
        one, two = dict(report), dict(report)
        one["rows"] = [r for r in report["rows"] if r["threads"] == 1]
        two["rows"] = [r for r in report["rows"] if r["threads"] == 2]
        r = plot(self.write_json("t1.json", one), self.write_json("t2.json", two),
                 "-o", self.dir, "--format", "png")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.dir, "scaling.png")))

    def test_invalid_rows_are_left_out(self):
        report = self.fixture()
        report["rows"][0]["valid"] = False
        r = plot(self.write_json("x.json", report), "-o", self.dir, "--format", "png")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("left out 1 invalid rows", r.stderr)
        for row in report["rows"]:
            row["valid"] = False
        r = plot(self.write_json("x.json", report), "-o", self.dir)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no valid rows to plot", r.stderr)

    def test_malformed_json_is_a_clear_error(self):
        with open(FIXTURE) as f:
            text = f.read()
        path = os.path.join(self.dir, "cut.json")
        with open(path, "w") as f:
            f.write(text[: len(text) // 2])
        out = os.path.join(self.dir, "charts")
        r = plot(path, "-o", out)
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"plot.py: error: {path}: line ", r.stderr)
        self.assertIn("not valid JSON", r.stderr)
        self.assertFalse(os.path.exists(out))  # nothing written

    def test_wrong_shapes_name_the_file_row_and_key(self):
        report = self.fixture()
        del report["rows"][3]["mrays_median"]
        r = plot(self.write_json("k.json", report), "-o", self.dir)
        self.assertEqual(r.returncode, 1)
        self.assertIn("k.json: rows[3]: missing key \"mrays_median\"", r.stderr)

        report = self.fixture()
        report["rows"][2]["threads"] = "two"
        r = plot(self.write_json("t.json", report), "-o", self.dir)
        self.assertEqual(r.returncode, 1)
        self.assertIn("t.json: rows[2].threads: expected an integer, found \"two\"", r.stderr)

        r = plot(self.write_json("list.json", [1, 2]), "-o", self.dir)
        self.assertEqual(r.returncode, 1)
        self.assertIn("list.json: expected an object with a \"rows\" array", r.stderr)

        r = plot(os.path.join(self.dir, "absent.json"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("absent.json: cannot read: No such file or directory", r.stderr)

    def test_usage_errors(self):
        r = plot(FIXTURE, "--format", "gif")
        self.assertEqual(r.returncode, 2)
        self.assertIn("unknown format \"gif\"", r.stderr)
        r = plot()
        self.assertEqual(r.returncode, 2)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
