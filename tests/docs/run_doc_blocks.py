#!/usr/bin/env python3
"""Runs the command blocks of README.md and docs/*.md, as a reader would.

Every fenced block tagged ``sh`` (or ``bash``) is a command block. An HTML comment on the line(s) just
before a block may adjust how it runs (the reader does not see it):

    <!-- doc-test: skip REASON -->                the block is not run; the reason is printed
    <!-- doc-test: sub OLD => NEW -->             replace the first OLD by NEW before running (repeatable,
                                                 one per line of the comment): shorter durations, a
                                                 bounded wait instead of an interactive one
    <!-- doc-test: dds -->                        the block talks DDS: it runs on the loopback
                                                 configuration and on a domain of its own (the default
                                                 domain of CYCLONEDDS_URI); `--domain 7` (any number) and
                                                 ROS_DOMAIN_ID=7 become that domain
    <!-- doc-test: timeout S -->                  give up after S seconds (default 60)
    <!-- doc-test: expect FILE -->                FILE must exist afterwards (besides those found below)

The blocks of one document run in order in one temporary folder (a later block may use an earlier one's
files). The folder holds links to the repository's examples/, config/, scripts/, bench/, web/, tests/ and the
build folder, so the paths the docs show work; `tetra` on PATH is the program built, and `build/tetra`
is it too; `build/python` is the Python package built beside it (when it is). A reader has only the README's
PATH step: every other document that says `tetra` must point to it (quote `export PATH=$PWD/build:$PATH`
and link the README's Quick start), or it fails. A block fails on a
non-zero exit status (bash -e, pipefail) or when a file it names as an output (-o, --out, --truth,
--attitude, --events, --json, --plot, --summary, --pointing, --write-unit, --kalibr, or an expect
directive) is missing afterwards. Processes a block leaves in the
background are stopped at its end.

Usage: run_doc_blocks.py --tetra BUILD/tetra --source REPO [--domain-base N] [--only FILE] [--list]
"""
import argparse
import glob
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^```\s*(\w*)\s*$")
MARKER = re.compile(r"<!--\s*doc-test:(.*?)-->", re.S)
OUTPUT_OPTIONS = ("-o", "--out", "--truth", "--attitude", "--events", "--json", "--plot", "--summary",
                  "--pointing", "--write-unit", "--kalibr")
PATH_STEP = "export PATH=$PWD/build:$PATH"
LINKED = ("examples", "config", "scripts", "bench", "web", "idl", "packaging", "tests")


class Block:
    def __init__(self, path, line, text, directives):
        self.path, self.line, self.text = path, line, text
        self.skip = None
        self.subs = []
        self.dds = False
        self.timeout = 60.0
        self.expect = []
        for d in directives:
            d = d.strip()
            if not d:
                continue
            word, _, rest = d.partition(" ")
            if word == "skip":
                self.skip = rest.strip() or "no reason given"
            elif word == "sub":
                old, sep, new = rest.partition("=>")
                if not sep:
                    raise SystemExit(f"{path}:{line}: doc-test sub without '=>': {d}")
                self.subs.append((old.strip(), new.strip()))
            elif word == "dds":
                self.dds = True
            elif word == "timeout":
                self.timeout = float(rest)
            elif word == "expect":
                self.expect.append(rest.strip())
            else:
                raise SystemExit(f"{path}:{line}: unknown doc-test directive '{word}'")

    def name(self, source):
        return f"{os.path.relpath(self.path, source)}:{self.line}"


def directives_before(lines, i):
    """The doc-test directives of the comment that ends on the last non-blank line before line i."""
    j = i - 1
    while j >= 0 and not lines[j].strip():
        j -= 1
    if j < 0 or not lines[j].rstrip().endswith("-->"):
        return []
    k = j
    while k >= 0 and "<!--" not in lines[k]:
        k -= 1
    m = MARKER.search("\n".join(lines[k:j + 1]))
    if not m:
        return []
    return [part for line in m.group(1).split("\n") for part in [line.strip()] if part]


def blocks_of(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        if m.group(1) in ("sh", "bash"):
            out.append(Block(path, i + 1, "\n".join(lines[i + 1:j]), directives_before(lines, i)))
        i = j + 1
    return out


def named_outputs(text):
    """Files the block names as outputs (relative to its folder); '-' and variables are left out."""
    files = []
    for line in text.split("\n"):
        words = line.split("#", 1)[0].split()
        for a, b in zip(words, words[1:]):
            if a in OUTPUT_OPTIONS and b != "-" and "$" not in b and not b.startswith("-"):
                files.append(b)
            elif a.startswith("--") and "=" in a and a.split("=", 1)[0] in OUTPUT_OPTIONS:
                files.append(a.split("=", 1)[1])
    return files


def lacks_path_step(path, source):
    """True for a document besides the README that says `tetra` and neither quotes the README's PATH step nor
    links the README's Quick start."""
    if os.path.samefile(path, os.path.join(source, "README.md")):
        return False
    text = open(path, encoding="utf-8").read()
    says_tetra = re.search(r"`tetra[ `]|^tetra ", text, re.M)
    return bool(says_tetra) and (PATH_STEP not in text or "README.md#quick-start" not in text)


def prepare(block, domain):
    text = block.text
    for old, new in block.subs:
        if old not in text:
            raise RuntimeError(f"doc-test sub: '{old}' is not in the block")
        text = text.replace(old, new, 1)
    if block.dds:
        text = re.sub(r"--domain \d+", f"--domain {domain}", text)
        text = re.sub(r"ROS_DOMAIN_ID=\d+", f"ROS_DOMAIN_ID={domain}", text)
    return text


def run_block(block, text, folder, env):
    script = "set -eo pipefail\n" + text + "\n"
    start = time.monotonic()
    # Output to a file, not a pipe: a process left in the background would hold a pipe open.
    with tempfile.TemporaryFile(mode="w+") as log:
        proc = subprocess.Popen(["bash", "-c", script], cwd=folder, env=env, stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True)
        try:
            status = proc.wait(timeout=block.timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            status = f"timeout after {block.timeout:.0f} s"
        log.seek(0)
        output = log.read()
    # Anything the block left running in the background (a service started with &).
    try:
        os.killpg(proc.pid, signal.SIGTERM)
        time.sleep(0.2)
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    return status, output, time.monotonic() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetra", required=True, help="the built program")
    ap.add_argument("--source", required=True, help="the repository")
    ap.add_argument("--domain-base", type=int, default=221, help="first DDS domain id of the dds blocks")
    ap.add_argument("--only", help="one document (path relative to the repository)")
    ap.add_argument("--list", action="store_true", help="list the blocks and what would be done")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folders")
    args = ap.parse_args()
    source = os.path.abspath(args.source)
    tetra = os.path.abspath(args.tetra)
    docs = [os.path.join(source, "README.md")] + sorted(glob.glob(os.path.join(source, "docs", "*.md")))
    if args.only:
        docs = [os.path.join(source, args.only)]

    bin_dir = tempfile.mkdtemp(prefix="tetra-doc-bin-")
    os.symlink(tetra, os.path.join(bin_dir, "tetra"))
    env = dict(os.environ)
    env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
    env.pop("CYCLONEDDS_URI", None)

    failures, ran, skipped = [], 0, 0
    domain = args.domain_base
    total_start = time.monotonic()
    for doc in docs:
        if lacks_path_step(doc, source):
            label = os.path.relpath(doc, source)
            failures.append(f"{label}: says `tetra` without the README's PATH step")
            print(f"FAIL {label}: says `tetra` without pointing to the README's PATH step ({PATH_STEP})")
        blocks = blocks_of(doc)
        if not blocks:
            continue
        folder = tempfile.mkdtemp(prefix="tetra-doc-")
        for name in LINKED:
            if os.path.exists(os.path.join(source, name)):
                os.symlink(os.path.join(source, name), os.path.join(folder, name))
        os.makedirs(os.path.join(folder, "build"))
        os.symlink(tetra, os.path.join(folder, "build", "tetra"))
        python_package = os.path.join(os.path.dirname(tetra), "python")  # build/python (docs/python.md)
        if os.path.isdir(python_package):
            os.symlink(python_package, os.path.join(folder, "build", "python"))
        for block in blocks:
            label = block.name(source)
            if block.skip:
                skipped += 1
                print(f"SKIP {label}: {block.skip}")
                continue
            try:
                text = prepare(block, domain)
            except RuntimeError as e:
                failures.append(f"{label}: {e}")
                print(f"FAIL {label}: {e}")
                continue
            if args.list:
                print(f"RUN  {label}{' (dds, domain %d)' % domain if block.dds else ''}:\n{text}\n")
                continue
            block_env = dict(env)
            if block.dds:
                # The loopback configuration with this block's domain as the default one, for the commands
                # the block runs without --domain.
                xml = open(os.path.join(source, "config", "cyclonedds-loopback.xml"), encoding="utf-8").read()
                config = os.path.join(bin_dir, f"cyclonedds-{domain}.xml")
                with open(config, "w", encoding="utf-8") as out:
                    out.write(xml.replace('<Domain Id="any">', f'<Domain Id="{domain}">'))
                block_env["CYCLONEDDS_URI"] = "file://" + config
                block_env["ROS_DOMAIN_ID"] = str(domain)
                domain += 1
            status, output, seconds = run_block(block, text, folder, block_env)
            ran += 1
            missing = [f for f in named_outputs(text) + block.expect
                       if not os.path.exists(os.path.join(folder, f))]
            if status != 0 or missing:
                why = f"exit status {status}" if status != 0 else "missing " + ", ".join(missing)
                failures.append(f"{label}: {why}")
                print(f"FAIL {label} ({seconds:.1f} s): {why}\n--- block as run:\n{text}\n--- output:\n"
                      f"{output[-4000:]}\n---")
            else:
                print(f"ok   {label} ({seconds:.1f} s)")
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)
        else:
            print(f"     kept {folder}")
    shutil.rmtree(bin_dir, ignore_errors=True)
    print(f"{ran} blocks run, {skipped} skipped, {len(failures)} failed, "
          f"{time.monotonic() - total_start:.0f} s")
    for f in failures:
        print("FAILED " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
