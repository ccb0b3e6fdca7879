#!/usr/bin/env python3
"""Keeps README.md's examples and sample output true.

    readme_examples.py OCTRAY README.md SOURCE_DIR

README.md marks what this test runs with HTML comments (invisible when rendered), each
directly before a fenced code block:

  <!-- readme-test: examples -->
      every line of the block is a command: run it, expect exit status 0
  <!-- readme-test: output of COMMAND -->
      the block is the sample output of COMMAND: run it and check that every line of the
      block (but "...") appears in the real output, in order, numbers aside

Every command runs through the shell with `octray` meaning the built OCTRAY, in a temporary
directory where `scene/` links to the source tree's (so `scene/examples/bounce.json`
resolves): the examples in one directory, in the order of the README (a later example may
use an earlier one's files), each sample output's command in a fresh one of its own. To keep the test fast, an `octray render`
command renders at most 64x36: its --width/--height values are replaced by 64 and 36, or
both options are appended. Commands with --crop keep their size (their pixel regions need
it), and so does `assemble`, which joins them. `--shard auto` reads the environment of
task 0 of a two-task Slurm array (SLURM_ARRAY_TASK_ID=0, SLURM_ARRAY_TASK_COUNT=2).

"Numbers aside": every number in a sample line matches any number, and an instruction
set name (avx512, avx2, sse4.1, sse2) any of them, since both depend on the machine.
"""

import os
import re
import shlex
import subprocess
import sys
import tempfile

SMALL = {"--width": "64", "--height": "36"}
ENV = {"SLURM_ARRAY_TASK_ID": "0", "SLURM_ARRAY_TASK_COUNT": "2"}
ISAS = ("avx512", "avx2", "sse4.1", "sse2")


def marked_blocks(readme_path):
    """[(marker text, [lines of the fenced block after it], line number of the marker)]."""
    with open(readme_path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    blocks = []
    for i, line in enumerate(lines):
        m = re.fullmatch(r"\s*<!-- readme-test: (.*?) -->\s*", line)
        if not m:
            continue
        if i + 1 >= len(lines) or not lines[i + 1].startswith("```"):
            sys.exit(f"{readme_path}:{i + 1}: a readme-test marker must be followed "
                     "directly by a ``` block")
        end = i + 2
        while end < len(lines) and not lines[end].startswith("```"):
            end += 1
        if end == len(lines):
            sys.exit(f"{readme_path}:{i + 2}: the ``` block is not closed")
        blocks.append((m.group(1), lines[i + 2:end], i + 1))
    return blocks


def small(words):
    """An `octray render` command's words at most 64x36 (see the docstring)."""
    if words[:2] != ["octray", "render"] or "--crop" in words:
        return words
    words = list(words)
    for option, value in SMALL.items():
        if option in words:
            words[words.index(option) + 1] = value
        else:
            words += [option, value]
    return words


def shell_command(line):
    """A README line as a shell command: comments dropped, each `octray` command small."""
    words = shlex.split(line)
    # A comment starts at a word that starts with # (as in the shell; `out/x.####.exr` is
    # no comment, and shlex's own comments would start there).
    words = words[:next((k for k, w in enumerate(words) if w.startswith("#")), len(words))]
    commands, current = [], []
    for word in words + ["&&"]:
        if word == "&&":
            commands.append(" ".join(shlex.quote(w) for w in small(current)))
            current = []
        else:
            current.append(word)
    return " && ".join(c for c in commands if c)


def run(command, cwd, octray):
    env = dict(os.environ, **ENV)
    env["PATH"] = os.path.dirname(octray) + os.pathsep + env["PATH"]
    return subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=120)


NUMBER = r"[0-9]+(?:\.[0-9]+)?"


def template(sample_line):
    """A regular expression for one sample line, numbers and ISA names aside."""
    out, pos = "", 0
    pattern = re.compile(r"[0-9]+(?:\.[0-9]+)?|" + "|".join(re.escape(i) for i in ISAS))
    for m in pattern.finditer(sample_line):
        out += re.escape(sample_line[pos:m.start()])
        out += NUMBER if m.group(0)[0].isdigit() else "(?:" + "|".join(
            re.escape(i) for i in ISAS) + ")"
        pos = m.end()
    out += re.escape(sample_line[pos:])
    # Columns are aligned with runs of spaces, whose width follows the numbers.
    return re.compile(re.sub(r"(\\ )+", r" +", out))


def check_shape(sample, stdout, stderr):
    """The sample's lines that are missing from the output (in order within a stream)."""
    streams = {"stdout": stdout.split("\n"), "stderr": stderr.split("\n")}
    next_line = {"stdout": 0, "stderr": 0}
    missing = []
    for line in sample:
        if line.strip() in ("", "..."):
            continue
        regex = template(line.rstrip())
        for name, lines in streams.items():
            found = next((k for k in range(next_line[name], len(lines))
                          if regex.fullmatch(lines[k].rstrip())), None)
            if found is not None:
                next_line[name] = found + 1
                break
        else:
            missing.append(line)
    return missing


def fresh_directory(parent, name, source):
    path = os.path.join(parent, name)
    os.mkdir(path)
    os.symlink(os.path.join(source, "scene"), os.path.join(path, "scene"))
    return path


def main():
    octray, readme, source = (os.path.abspath(a) for a in sys.argv[1:4])
    blocks = marked_blocks(readme)
    failures, commands, samples = [], 0, 0
    with tempfile.TemporaryDirectory(prefix="octray-readme-") as tmp:
        examples_dir = fresh_directory(tmp, "examples", source)
        for marker, block, line_number in blocks:
            if marker == "examples":
                for k, line in enumerate(block):
                    if not line.strip() or line.lstrip().startswith("#"):
                        continue
                    command = shell_command(line)
                    commands += 1
                    r = run(command, examples_dir, octray)
                    where = f"README.md:{line_number + 2 + k}"
                    print(f"{where}: {command}: exit {r.returncode}")
                    if r.returncode != 0:
                        failures.append(f"{where}: `{line.strip()}` (run as `{command}`) "
                                        f"exited {r.returncode}:\n{r.stdout}{r.stderr}")
            elif marker.startswith("output of "):
                command = shell_command(marker[len("output of "):].strip("` "))
                samples += 1
                r = run(command, fresh_directory(tmp, f"sample{samples}", source), octray)
                print(f"README.md:{line_number}: {command}: exit {r.returncode}")
                missing = check_shape(block, r.stdout, r.stderr)
                if r.returncode != 0 or missing:
                    failures.append(
                        f"README.md:{line_number}: the sample output of `{command}` "
                        f"(exit {r.returncode}) does not match; missing, in order:\n  " +
                        "\n  ".join(missing) + f"\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}")
            else:
                failures.append(f"README.md:{line_number}: unknown readme-test marker "
                                f"\"{marker}\" (expected examples or output of COMMAND)")
    if commands == 0 or samples == 0:
        failures.append(f"{readme}: expected readme-test markers for examples and for "
                        f"sample output; found {commands} commands, {samples} samples")
    for failure in failures:
        print("FAIL " + failure, file=sys.stderr)
    print(f"readme_examples: {commands} commands, {samples} sample outputs, "
          f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
