#!/usr/bin/env python3
"""The docs test: every fenced block of README.md and docs/*.md is built, run or checked.

Like Rust's doctests, the text users copy from is what CI runs. Each block is one of:

  ```cpp``` with `int main(`    a whole program: built as a user's CMake project (the README's
                                cmake block, find_package with CMAKE_PREFIX_PATH=the installed
                                copy) and run with -nogui -simclock (plus the annotation's args)
  ```cpp``` fragment            compiled inside the wrapper its page names:
                                <!-- doc-test: fragment NAME -->  (tests/docs/wrappers/NAME.cpp,
                                whose line @FRAGMENT@ the block replaces); `fragment NAME run`
                                also runs the program (-nogui -simclock)
  ```cmake```                   <!-- doc-test: cmake --> the lines a user adds to their project
  ```sh```                      each command line run (continuations joined, comments dropped)
                                in a scratch folder with the installed bin/ first on PATH, `build`
                                linking to the build tree, `scripts`, `tests` and `examples` to the source
                                tree's; exit status 0.
                                <!-- doc-test: server -->: each command must still run after 2 s
                                and end with status 0 on SIGTERM; `rp.cfg above` in the annotation:
                                the page's last rp.cfg block above is the folder's rp.cfg. A
                                command whose comment starts with a quoted text (`# "..."` or
                                `# prints "..."`) must print a line matching it (numbers may
                                differ; words in capitals, such as PORT, stand for any word);
                                <!-- doc-test: script -->: the block runs as one bash script
                                (set -euo pipefail) that must end with status 0
  ``` (rp.cfg: starts with [name]) written to rp.cfg and checked with `rp-objects -sim -config`
                                (exit status 0); <!-- doc-test: rp.cfg FILE... --> copies FILEs
                                (source-tree paths, `SRC:NAME` to rename) next to it
  ``` output sample             <!-- doc-test: output [rp.cfg above] [status=N] COMMAND [;; ...] -->: each
                                command must end with status N (default 0) and every line of the
                                block must match a line it printed; numbers may differ, `...`
                                stands for anything
  any block                     <!-- doc-test: skip (REASON) --> is not run; the reason is required

The annotation is an HTML comment on the line(s) right before the block (blank lines allowed).
A block that is none of these fails the test: nothing in the docs goes unchecked by accident.

usage: doc_test.py --source SRC --build BUILD --work DIR [--generator G] [--only PAGE]
"""
import argparse
import glob
import os
import re
import shutil
import signal
import subprocess
import sys
import time

ANNOTATION = re.compile(r"<!--\s*doc-test:\s*(.*?)\s*-->", re.S)


class Block:
    def __init__(self, page, line, lang, body, annotation):
        self.page, self.line, self.lang, self.body, self.annotation = page, line, lang, body, annotation

    def where(self):
        return f"{self.page}:{self.line}"


def parse_page(path, rel):
    lines = open(path, encoding="utf-8").read().split("\n")
    blocks = []
    i = 0
    while i < len(lines):
        m = re.match(r"^(\s*)```(\S*)\s*$", lines[i])
        if not m:
            i += 1
            continue
        indent, lang = len(m.group(1)), m.group(2)
        j = i + 1
        while j < len(lines) and not re.match(r"^\s*```\s*$", lines[j]):
            j += 1
        if j >= len(lines):
            raise SystemExit(f"{rel}:{i + 1}: unterminated code block")
        body = "\n".join(l[indent:] if l[:indent].strip() == "" else l for l in lines[i + 1:j])
        # The annotation: the comment that ends on the nearest non-blank line above the block.
        k = i - 1
        while k >= 0 and lines[k].strip() == "":
            k -= 1
        annotation = None
        if k >= 0 and lines[k].rstrip().endswith("-->"):
            start = k
            while start >= 0 and "<!--" not in lines[start]:
                start -= 1
            m2 = ANNOTATION.search("\n".join(lines[start:k + 1]))
            if m2:
                annotation = " ".join(m2.group(1).split())
        blocks.append(Block(rel, i + 1, lang, body, annotation))
        i = j + 1
    return blocks


def run(cmd, cwd, env, timeout, shell=False):
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, cwd=cwd, env=env, shell=shell, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         executable="/bin/bash" if shell else None, start_new_session=True)
    try:
        out, _ = p.communicate(timeout=timeout)
        return p.returncode, out.decode("utf-8", "replace"), time.monotonic() - t0
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)  # the command and everything it started
        out, _ = p.communicate()
        return None, out.decode("utf-8", "replace") + f"\n(timed out after {timeout} s)", time.monotonic() - t0


def shell_commands(body):
    """The command lines of a sh block: continuations joined, comments and blank lines dropped.
    Returns (command, sample) pairs: `sample` is the quoted text of a trailing comment that starts
    with a quoted string (`# "gripper: Close done"` or `# prints "netft 127.0.0.1:PORT"`), else None."""
    commands, current = [], ""
    for raw in body.split("\n"):
        line = raw.rstrip()
        if current == "" and (line.strip() == "" or line.lstrip().startswith("#")):
            continue
        if line.endswith("\\"):
            current += line[:-1] + " "
            continue
        current += line
        # A trailing comment (" # ..." outside quotes) is dropped.
        out, quote = "", None
        for idx, ch in enumerate(current):
            if quote:
                quote = None if ch == quote else quote
            elif ch in "'\"":
                quote = ch
            elif ch == "#" and (idx == 0 or current[idx - 1] in " \t"):
                break
            out += ch
        comment = current[len(out):]
        m = re.match(r'#\s*(?:prints\s+)?"([^"]+)"', comment)
        commands.append((out.strip(), m.group(1) if m else None))
        current = ""
    return commands


def line_pattern(doc_line, placeholders=False):
    """A regular expression for a line of an output sample: numbers may differ, `...` is anything
    (and with `placeholders`, a word in capitals such as PORT or N stands for any word)."""
    pattern = ""
    split = r"(\.\.\.|-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?" + (r"|\b[A-Z]{1,}\b)" if placeholders else ")")
    for token in re.split(split, doc_line.strip()):
        if token == "...":
            pattern += ".*"
        elif placeholders and re.fullmatch(r"[A-Z]+", token or ""):
            pattern += r"\S+"
        elif re.fullmatch(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", token or "x"):
            pattern += r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
        else:
            pattern += re.sub(r"(?:\\ )+", r"\\s+", re.escape(token))
    return re.compile(pattern)


class DocTest:
    def __init__(self, args):
        self.src = os.path.abspath(args.source)
        self.build = os.path.abspath(args.build)
        self.work = os.path.abspath(args.work)
        self.generator = args.generator
        self.prefix = os.path.join(self.work, "prefix")
        self.failures = []
        self.counts = {}
        env = dict(os.environ)
        env.pop("LD_LIBRARY_PATH", None)
        env.pop("RP_WEB_ROOT", None)
        env["PATH"] = os.path.join(self.prefix, "bin") + os.pathsep + env.get("PATH", "")
        self.env = env

    def fail(self, block, message):
        self.failures.append(f"{block.where()}: {message}")
        print(f"FAIL {block.where()}: {message}", flush=True)

    def count(self, kind):
        self.counts[kind] = self.counts.get(kind, 0) + 1

    def scratch(self, block):
        d = os.path.join(self.work, re.sub(r"[^A-Za-z0-9]+", "_", block.where()))
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
        return d

    def install(self):
        shutil.rmtree(self.prefix, ignore_errors=True)
        rc, out, _ = run(["cmake", "--install", self.build, "--prefix", self.prefix], self.work, self.env, 600)
        if rc != 0:
            raise SystemExit(f"doc_test: cmake --install failed ({rc}):\n{out}")

    # ---- C++ ------------------------------------------------------------------------------
    def cpp_jobs(self, blocks):
        """Builds every C++ block in one user project; returns the blocks to run with their programs."""
        cmake_blocks = [b for b in blocks if b.lang == "cmake"]
        for b in cmake_blocks:
            if b.annotation != "cmake" and not (b.annotation or "").startswith("skip"):
                self.fail(b, "a cmake block needs <!-- doc-test: cmake --> or a skip annotation")
        user_cmake = [b for b in cmake_blocks if b.annotation == "cmake"]
        if len(user_cmake) != 1:
            raise SystemExit("doc_test: expected exactly one <!-- doc-test: cmake --> block (the README's), found "
                             + str(len(user_cmake)))
        project_lines = user_cmake[0].body
        root = os.path.join(self.work, "cpp")
        shutil.rmtree(root, ignore_errors=True)
        os.makedirs(root)
        top = ["cmake_minimum_required(VERSION 3.25)", "project(doc_examples CXX)"]
        jobs = []
        for b in blocks:
            if b.lang != "cpp" or (b.annotation or "").startswith("skip"):
                continue
            ann = (b.annotation or "").split()
            whole = "int main(" in b.body
            if whole and (not ann or ann[0] == "program"):
                source, run_args, kind = b.body + "\n", ann[1:], "program"
            elif ann and ann[0] == "fragment" and len(ann) >= 2:
                wrapper = os.path.join(self.src, "tests", "docs", "wrappers", ann[1] + ".cpp")
                if not os.path.exists(wrapper):
                    self.fail(b, f"the wrapper '{ann[1]}' does not exist ({wrapper})")
                    continue
                text = open(wrapper, encoding="utf-8").read()
                if "@FRAGMENT@" not in text:
                    self.fail(b, f"the wrapper {wrapper} has no @FRAGMENT@ line")
                    continue
                # The fragment's own #include lines go first, at file scope (as Rust hoists `use`).
                includes = "\n".join(l for l in b.body.split("\n") if l.startswith("#include"))
                body = "\n".join("" if l.startswith("#include") else l for l in b.body.split("\n"))
                source = includes + "\n" + text.replace(
                    "@FRAGMENT@", f'#line {b.line + 1} "{b.page}"\n{body}\n#line 1 "{ann[1]}.cpp"')
                run_args = None if len(ann) < 3 or ann[2] != "run" else ann[3:]
                kind = "fragment"
            else:
                self.fail(b, "a C++ fragment needs <!-- doc-test: fragment WRAPPER --> (or a whole program, "
                             "or a skip annotation)")
                continue
            name = re.sub(r"[^A-Za-z0-9]+", "_", b.where())
            d = os.path.join(root, name)
            os.makedirs(d)
            open(os.path.join(d, "main.cpp"), "w", encoding="utf-8").write(source)
            # The user's project: their program and the README's two lines.
            open(os.path.join(d, "CMakeLists.txt"), "w", encoding="utf-8").write(
                "add_executable(myprogram main.cpp)\n" + project_lines + "\n"
                + f"set_target_properties(myprogram PROPERTIES OUTPUT_NAME {name})\n")
            top.append(f"add_subdirectory({name})")
            jobs.append((b, kind, name, run_args))
            self.count("C++ " + kind)
        # add_executable(myprogram) in each folder would clash: give each folder its own target name.
        for b, kind, name, _ in jobs:
            path = os.path.join(root, name, "CMakeLists.txt")
            text = open(path, encoding="utf-8").read()
            open(path, "w", encoding="utf-8").write(re.sub(r"\bmyprogram\b", name, text))
        open(os.path.join(root, "CMakeLists.txt"), "w", encoding="utf-8").write("\n".join(top) + "\n")
        configure = ["cmake", "-S", root, "-B", os.path.join(root, "build"), "-G", self.generator,
                     "-DCMAKE_BUILD_TYPE=Release", f"-DCMAKE_PREFIX_PATH={self.prefix}"]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        rc, out, _ = run(configure, root, self.env, 600)
        if rc != 0:
            raise SystemExit(f"doc_test: configuring the user project failed ({rc}):\n{out}")
        built = []
        # -k 0: build every block; report each that fails by its page and line.
        rc, out, secs = run(["cmake", "--build", os.path.join(root, "build"), "-j2", "--", "-k", "0"], root,
                            self.env, 1800)
        print(f"doc_test: built {len(jobs)} C++ blocks in {secs:.0f} s", flush=True)
        for b, kind, name, run_args in jobs:
            exe = os.path.join(root, "build", name, name)
            if not os.path.exists(exe):
                errors = [l for l in out.split("\n") if b.page in l or f"{name}/" in l]
                self.fail(b, f"the {kind} does not compile:\n    " + "\n    ".join(errors[:15] or out.split("\n")[-30:]))
                continue
            if run_args is not None:
                built.append((b, exe, run_args))
        return built

    def run_programs(self, built):
        for b, exe, run_args in built:
            d = self.scratch(b)
            # files=SRC[:NAME],...: source-tree files copied next to the program first.
            for a in [a for a in run_args if a.startswith("files=")]:
                for f in a[len("files="):].split(","):
                    src, _, name = f.partition(":")
                    shutil.copy(os.path.join(self.src, src), os.path.join(d, name or os.path.basename(src)))
            run_args = [a for a in run_args if not a.startswith("files=")]
            rc, out, secs = run([exe, "-nogui", "-simclock"] + run_args, d, self.env, 300)
            if rc != 0:
                self.fail(b, f"the program exited with {rc}:\n{out[-3000:]}")
            else:
                print(f"ok   {b.where()}: ran ({secs:.1f} s)", flush=True)

    # ---- shell, rp.cfg, output samples ------------------------------------------------------
    def link_trees(self, d):
        os.symlink(self.build, os.path.join(d, "build"))
        os.symlink(os.path.join(self.src, "scripts"), os.path.join(d, "scripts"))
        os.symlink(os.path.join(self.src, "tests"), os.path.join(d, "tests"))  # fixtures of output samples
        os.symlink(os.path.join(self.src, "examples"), os.path.join(d, "examples"))  # the example programs' sources
        os.makedirs(os.path.join(d, "docs", "images", "trajectories"))

    def write_rpcfg_above(self, b, blocks, d):
        """Writes the last rp.cfg block above `b` on its page to d/rp.cfg; false if there is none."""
        above = [o for o in blocks if o.page == b.page and o.line < b.line and o.lang == "" and
                 re.match(r"^\s*\[[A-Za-z0-9_-]+\]", o.body.lstrip("\n"))]
        if not above:
            self.fail(b, "no rp.cfg block above it on its page")
            return False
        open(os.path.join(d, "rp.cfg"), "w", encoding="utf-8").write(above[-1].body + "\n")
        return True

    def check_sh(self, b, blocks):
        d = self.scratch(b)
        self.link_trees(d)
        commands = shell_commands(b.body)
        if not commands:
            self.fail(b, "a sh block without commands")
        ann = b.annotation or ""
        if "rp.cfg above" in ann and not self.write_rpcfg_above(b, blocks, d):
            return
        samples = {c: sample for c, sample in commands}
        commands = [c for c, _ in commands]
        if ann.startswith("script"):  # the whole block as one bash script, stopping at the first error
            rc, out, secs = run("set -euo pipefail\n" + b.body, d, self.env, 120, shell=True)
            self.count("script")
            if rc != 0:
                self.fail(b, f"the script exited with {rc}:\n{out[-3000:]}")
            else:
                print(f"ok   {b.where()}: script ({secs:.1f} s)", flush=True)
            return
        if ann.startswith("server"):
            for c in commands:
                self.count("server command")
                p = subprocess.Popen(c, cwd=d, env=self.env, shell=True, executable="/bin/bash",
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
                time.sleep(2)
                if p.poll() is not None:
                    out, _ = p.communicate()
                    self.fail(b, f"`{c}` ended with {p.returncode} instead of serving:\n{out.decode()[-3000:]}")
                    continue
                os.killpg(p.pid, signal.SIGTERM)
                try:
                    out, _ = p.communicate(timeout=60)
                except subprocess.TimeoutExpired:
                    os.killpg(p.pid, signal.SIGKILL)
                    out, _ = p.communicate()
                    self.fail(b, f"`{c}` did not end within 60 s of SIGTERM")
                    continue
                text = out.decode("utf-8", "replace")
                if p.returncode != 0 or not text.strip():
                    self.fail(b, f"`{c}` ended with {p.returncode} after SIGTERM:\n{text[-3000:]}")
                else:
                    print(f"ok   {b.where()}: `{c}` served, ended with 0 on SIGTERM", flush=True)
            return
        for c in commands:
            rc, out, secs = run(c, d, self.env, 120, shell=True)
            self.count("shell command")
            sample = samples.get(c)
            if rc != 0:
                self.fail(b, f"`{c}` exited with {rc}:\n{out[-3000:]}")
            elif sample and not any(line_pattern(sample, True).fullmatch(l.strip()) for l in out.split("\n")):
                self.fail(b, f"`{c}` did not print \"{sample}\" (its comment says so); it printed:\n{out[-3000:]}")
            else:
                print(f"ok   {b.where()}: `{c}` ({secs:.1f} s)" + (f", printed \"{sample}\"" if sample else ""), flush=True)

    def check_rpcfg(self, b, files):
        d = self.scratch(b)
        open(os.path.join(d, "rp.cfg"), "w", encoding="utf-8").write(b.body + "\n")
        for f in files:
            src, _, name = f.partition(":")
            shutil.copy(os.path.join(self.src, src), os.path.join(d, name or os.path.basename(src)))
        rc, out, _ = run(["rp-objects", "-sim", "-config", "rp.cfg"], d, self.env, 120)
        self.count("rp.cfg")
        if rc != 0:
            self.fail(b, f"rp-objects -sim -config rp.cfg exited with {rc}:\n{out}")
        else:
            print(f"ok   {b.where()}: rp.cfg accepted by rp-objects", flush=True)

    def check_output(self, b, spec, blocks):
        status = 0
        d = self.scratch(b)
        self.link_trees(d)
        if spec.startswith("rp.cfg above"):
            if not self.write_rpcfg_above(b, blocks, d):
                return
            spec = spec[len("rp.cfg above"):].strip()
        m = re.match(r"status=(\d+)\s+(.*)", spec)
        if m:
            status, spec = int(m.group(1)), m.group(2)
        printed = []
        for c in [c.strip() for c in spec.split(";;")]:
            rc, out, _ = run(c, d, self.env, 300, shell=True)
            if rc != status:
                self.fail(b, f"`{c}` exited with {rc}, not {status}:\n{out[-3000:]}")
            printed += out.split("\n")
        self.count("output sample")
        missing = [l for l in b.body.split("\n") if l.strip() and not any(line_pattern(l).fullmatch(p.strip())
                                                                              for p in printed)]
        if missing:
            self.fail(b, "lines of the sample the commands did not print:\n    " + "\n    ".join(missing)
                      + "\n  they printed:\n    " + "\n    ".join(printed[:40]))
        else:
            print(f"ok   {b.where()}: output sample matches", flush=True)

    def main(self, pages):
        t0 = time.monotonic()
        os.makedirs(self.work, exist_ok=True)
        self.install()
        blocks = []
        for rel in pages:
            blocks += parse_page(os.path.join(self.src, rel), rel)
        for b in blocks:
            ann = b.annotation or ""
            if ann.startswith("skip"):
                if not re.match(r"skip\s*\(.+\)", ann):
                    self.fail(b, "a skip annotation needs its reason: <!-- doc-test: skip (REASON) -->")
                self.count("skipped")
                print(f"skip {b.where()}: {ann[4:].strip()}", flush=True)
        built = self.cpp_jobs(blocks)
        for b in blocks:
            ann = b.annotation or ""
            if ann.startswith("skip") or b.lang in ("cpp", "cmake"):
                continue
            if b.lang == "sh":
                self.check_sh(b, blocks)
            elif b.lang == "" and ann.startswith("output"):
                self.check_output(b, ann[len("output"):].strip(), blocks)
            elif b.lang == "" and re.match(r"^\s*\[[A-Za-z0-9_-]+\]", b.body.lstrip("\n")) and \
                    (ann == "" or ann.startswith("rp.cfg")):
                self.check_rpcfg(b, ann.split()[1:])
            else:
                self.fail(b, f"a ```{b.lang} block the test cannot check: annotate it (output, rp.cfg or skip)")
        self.run_programs(built)
        summary = ", ".join(f"{n} {k}" for k, n in sorted(self.counts.items()))
        print(f"doc_test: {len(blocks)} blocks in {len(pages)} pages ({summary}); {len(self.failures)} failures; "
              f"{time.monotonic() - t0:.0f} s")
        if self.failures:
            print("\nFailures:\n" + "\n".join(self.failures))
            return 1
        return 0


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--source", required=True)
    p.add_argument("--build", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--generator", default="Ninja")
    p.add_argument("--only", action="append", help="a page (relative to the source tree) to check alone")
    args = p.parse_args()
    src = os.path.abspath(args.source)
    pages = args.only or ["README.md"] + sorted(os.path.relpath(f, src) for f in glob.glob(os.path.join(src, "docs", "*.md")))
    return DocTest(args).main(pages)


if __name__ == "__main__":
    sys.exit(main())
