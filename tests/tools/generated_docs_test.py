#!/usr/bin/env python3
"""The man pages and shell completions the build generates (build/<preset>/share, what
`cmake --install` installs) against the command line itself.

    generated_docs_test.py OCTRAY SHARE_DIR

The commands and options come from `octray --help` and `octray COMMAND --help`, read as a
user reads them, not from the generator's own description, so a page or script that
misses a command, an option or part of an option's help fails. Every page must also
format without a single groff warning (`groff -man -Tutf8 -ww -z`), and equal what
`octray man COMMAND` prints now (a stale build output fails).
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

OCTRAY, SHARE = sys.argv[1], sys.argv[2]
MAN1 = os.path.join(SHARE, "man", "man1")
BASH = os.path.join(SHARE, "bash-completion", "completions", "octray")
ZSH = os.path.join(SHARE, "zsh", "vendor-completions", "_octray")
DESCRIPTION_COLUMN = 30  # where CLI11's --help starts an option's description


def octray(*args):
    return subprocess.run([OCTRAY, *args], capture_output=True, text=True, timeout=60)


def commands():
    """The subcommands that `octray --help` lists."""
    names, inside = [], False
    for line in octray("--help").stdout.split("\n"):
        if line.startswith("Subcommands:"):
            inside = True
        elif inside and not line.strip():
            break
        elif inside:
            names.append(line.split()[0])
    return names


def help_options(command):
    """{"--output": (all names, the whole description)} from `octray COMMAND --help`."""
    options, current = {}, None
    for line in octray(command, "--help").stdout.split("\n"):
        if re.match(r"  -", line):
            names = [n for n in line.split()[0].split(",") if n.startswith("-")]
            current = {"names": names, "text": line[DESCRIPTION_COLUMN:].strip()
                       if len(line[:DESCRIPTION_COLUMN].rstrip()) < DESCRIPTION_COLUMN else ""}
            for n in names:
                options[n] = current
        elif current is not None and line.startswith(" " * DESCRIPTION_COLUMN):
            current["text"] += " " + line.strip()
        else:
            current = None
    return options


def plain(roff):
    """The words of a man page's source without the markup, whitespace collapsed."""
    words = []
    for line in roff.split("\n"):
        macro = re.match(r"\.(B|BR|BI|I|SH|SS)\b ?", line)
        if macro:
            words.append(line[macro.end():])  # the macro's words are text
        elif not line.startswith("."):
            words.append(line)  # other requests (.TH, .TP, .RS 4, ...) carry no text
    text = "\n".join(words)
    text = re.sub(r"\\f[BIRP]", "", text)
    text = text.replace("\\-", "-").replace("\\e", "\\").replace("\\&", "")
    return " ".join(text.replace('"', " ").split())


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


class GeneratedDocsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = commands()
        # The app's commands as the parser knows them; `man` and `completion` included.
        for name in ("render", "scene", "compare", "bench", "verify", "info", "assemble",
                     "man", "completion"):
            assert name in cls.commands, f"octray --help does not list {name}"

    def test_a_page_per_command_and_no_other(self):
        expected = {"octray.1"} | {f"octray-{c}.1" for c in self.commands}
        self.assertEqual(set(os.listdir(MAN1)), expected)

    def test_pages_are_current_and_format_without_warnings(self):
        groff = shutil.which("groff")
        self.assertIsNotNone(groff, "groff (Debian groff-base) is needed to check the pages")
        for command in [""] + self.commands:
            page = os.path.join(MAN1, f"octray-{command}.1" if command else "octray.1")
            with self.subTest(page=page):
                text = read(page)
                self.assertEqual(text, octray("man", *([command] if command else [])).stdout)
                r = subprocess.run([groff, "-man", "-Tutf8", "-ww", "-z", page],
                                   capture_output=True, text=True, timeout=60)
                self.assertEqual((r.returncode, r.stderr), (0, ""))
                for section in ("NAME", "SYNOPSIS", "DESCRIPTION", "OPTIONS", "EXIT STATUS",
                                "SEE ALSO"):
                    self.assertRegex(text, rf'\n\.SH "?{section}"?\n')

    def test_every_option_with_its_whole_help_in_its_page(self):
        program = plain(read(os.path.join(MAN1, "octray.1")))
        for command in self.commands:
            self.assertIn(f"octray-{command}(1)", program.replace(" (1)", "(1)"))
            page_source = read(os.path.join(MAN1, f"octray-{command}.1"))
            page = plain(page_source)
            options = help_options(command)
            self.assertGreater(len(options), 0, command)
            for name, option in options.items():
                with self.subTest(command=command, option=name):
                    self.assertIn(", ".join(option["names"]), page)
                    self.assertIn(option["text"], page)
            # What --help's footer says: its examples and exit statuses are in the page.
            help_text = octray(command, "--help").stdout
            if "\nExamples:\n" in help_text:
                self.assertIn("\n.SH EXAMPLES\n", page_source)
                first = " ".join(help_text.split("\nExamples:\n")[1].split("\n")[0].split())
                self.assertIn(first, page)
            # A command without a table of its own has the program's.
            table = help_text if "\nExit codes" in help_text else octray("--help").stdout
            statuses = re.findall(r"^ {0,2}([0-9]+)  ", table.split("\nExit codes")[-1], re.M)
            prose = re.search(r"\nExit codes: (.*?)(\n\n|$)", help_text, re.S)
            if prose:  # "Exit codes: 0 when ..., 1 otherwise": the page says the same
                self.assertIn(" ".join(prose.group(1).split()), page)
                continue
            self.assertIn("0", statuses, command)
            for status in statuses:
                self.assertRegex(page_source, rf"\n\.B {status}\n")
        # The program's own options.
        for name in ("-h", "--help", "-V", "--version"):
            self.assertIn(name, program)

    def test_every_option_in_both_completions(self):
        bash, zsh = read(BASH), read(ZSH)
        self.assertEqual(bash, octray("completion", "bash").stdout)
        self.assertEqual(zsh, octray("completion", "zsh").stdout)
        self.assertEqual(subprocess.run(["bash", "-n", BASH]).returncode, 0)
        for command in self.commands:
            words = re.search(rf'\n        {re.escape(command)}\) words="([^"]*)"', bash)
            self.assertIsNotNone(words, f"bash: no case for {command}")
            words = words.group(1).split()
            self.assertIn(f"        '{command}:", zsh)
            for name in help_options(command):
                with self.subTest(command=command, option=name):
                    self.assertIn(name, words)
                    self.assertIn(f"'{name}[", zsh)

    def test_man_command(self):
        r = octray("man", "rendr")
        self.assertEqual(r.returncode, 2)
        self.assertIn('unknown command "rendr" (did you mean "render"?)', r.stderr)
        self.assertIn("Run 'octray man --help' for more information.", r.stderr)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "new", "man1")  # created
            r = octray("man", "bench", "--directory", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(os.listdir(out), ["octray-bench.1"])
            self.assertIn(f"wrote {os.path.join(out, 'octray-bench.1')}", r.stderr)
            blocker = os.path.join(tmp, "file")
            open(blocker, "w").close()
            r = octray("man", "--directory", os.path.join(blocker, "man1"))
            self.assertEqual(r.returncode, 4)
            self.assertIn("octray: I/O error: cannot create the directory", r.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
