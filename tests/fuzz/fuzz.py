#!/usr/bin/env python3
"""Hostile-input suite: deterministic mutations of hysteron's shipped scenes.

Every scene in prm/ (and any given with --scene) is mutated one way at a time:

  numbers      0, negative, NaN, inf, +-1e300, 1e-300, 2^31-1, 2^32+1, non-numbers, empty,
               one component of a list replaced, a list one entry short or long
  expressions  division by zero, NaN, sqrt(-1), rand(), unknown names, broken syntax
  strings      empty, 100,000 characters, non-ASCII, blanks, shell metacharacters
  structure    an `end` missing or extra, a duplicated or unknown entry, an unknown
               subsection, `include` of itself / a missing file / a directory / a binary
               file, CRLF line ends, a byte-order mark, a NUL byte, invalid UTF-8, a
               truncated file, an empty or comment-only file, a 1 MiB line, deep nesting
  files        an input file (mesh, shared library) that is missing, a directory, binary,
               empty, 200 MB, or garbage; an output directory that is a file, not creatable,
               or has a 300-character name
  command line --resume with no checkpoint, the file twice

Two more families (each with rules of its own, in their modules):

  inconsistent inputs that parse but are physically wrong (tests/fuzz/consistency.py):
               conflicting boundary conditions, nearly incompressible material on elements
               that lock, runs far beyond the memory, damaged Gmsh meshes (of the scenes
               given with --mesh-scene, by default the Gmsh scenes of tests/fem)
  faults       faults during a run (tests/fuzz/faults.py): a damaged, truncated or stale
               checkpoint, an input edited before --resume, a full disk under each kind of
               output file, a killed MPI rank

The list of all mutations is built in a fixed order and shuffled with --seed, so a seed and
a count name the same runs on every machine. Each mutation runs in its own directory with
--quiet and a time limit; runs longer than a step budget are stopped through the
HYSTERON_TEST_SIGNAL hook (SIGTERM after --steps steps, exit status 4 with a checkpoint),
so that a mutation that keeps a scene valid costs what the first steps cost.

Each run must satisfy:
  - no signal, and exit status 0, 1, 2 or (the step budget) 4 only; 3 is an internal error
  - it ends within --limit seconds (else: a hang)
  - exit 1 prints "error:" naming a parameter path (Subsection/Entry, file:line, or the
    mutated entry) and leaves no file at all in the working directory
  - exit 0, 2 and 4 leave no *.tmp, and the tables of exit 0 and 4 hold no NaN or inf
    (a non-finite number in an accepted run's output is a silent wrong answer)

  fuzz.py --hysteron build/hysteron --count 40 --inconsistent 8 --faults 4   quick subset (ctest)
  fuzz.py --hysteron build/hysteron --count 1200 --jobs 2 --report doc/reliability.md

Exit status 0 when every run satisfies the rules; the failures are printed otherwise.
"""
import argparse
import concurrent.futures
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import consistency  # noqa: E402
import faults  # noqa: E402

NUMBERS = ["0", "-1", "-0.0", "nan", "NaN", "inf", "-inf", "1e300", "-1e300", "1e-300",
           "-1e-300", "2147483647", "4294967297", "1e19", "abc", "", "0x1p3", "1e", "--1",
           "1 2", "1,,2"]
EXPRESSIONS = ["1/0", "nan", "sqrt(-1)", "log(0)", "rand()", "t/0", "(", "x*", "1e308*1e308",
               "unknown_name", "0*t+nan", "1e300*t"]
STRINGS = ["", "x" * 100000, "\u00fcn\u00efc\u00f8d\u00e9 \u20ac\u6f22\u5b57", "no such name",
           "   ", "\t", "*", "$(touch pwned); rm -rf /", "a,b,c,d,e,f,g,h"]
BOOLS = ["maybe", "", "2", "TRUE"]
NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
# The place an error names: a parameter path (Subsection/Entry), a file and line, or for
# command-line mistakes the command line or the option.
PATH_IN_MESSAGE = re.compile(r"([A-Za-z][\w'. ()-]*/[A-Za-z][\w'. ()-]*)|(\.prm:\d+)|"
                             r"(error: (command line|--[a-z-]+):)")


class Scene:
    """A parameter file as lines, with the subsection path and key of every `set`."""

    def __init__(self, path):
        self.path = path
        self.name = os.path.splitext(os.path.basename(path))[0]
        with open(path, encoding="utf-8") as f:
            self.lines = f.read().split("\n")
        self.entries = []  # (line index, section path, key, value)
        self.ends = []
        self.subsections = []
        stack = []
        for i, line in enumerate(self.lines):
            words = line.split("#", 1)[0].strip()
            if words.startswith("subsection "):
                stack.append(words[len("subsection "):].strip())
                self.subsections.append(i)
            elif words == "end":
                self.ends.append(i)
                if stack:
                    stack.pop()
            elif words.startswith("set ") and "=" in words:
                key, value = words[4:].split("=", 1)
                self.entries.append((i, "/".join(stack), key.strip(), value.strip()))
        self.inputs = [value for _, _, key, value in self.entries
                       if key in ("Mesh file", "File") and value]


def value_mutations(key, value):
    """Replacement values for one entry, by the kind of its current value."""
    parts = [p.strip() for p in value.split(",")]
    if value and NUMBER.match(value):
        return NUMBERS
    if len(parts) > 1 and all(NUMBER.match(p) for p in parts):
        out = []
        for k in range(len(parts)):
            for n in ["nan", "inf", "-1e300", "1e300", "abc", ""]:
                out.append(", ".join(parts[:k] + [n] + parts[k + 1:]))
        out.append(", ".join(parts[:-1]))
        out.append(", ".join(parts + [parts[-1]]))
        return out
    if value.lower() in ("true", "false"):
        return BOOLS
    if re.search(r"file|librar", key, re.I):
        return ["@missing", "@directory", "@binary", "@empty", "@huge", "@garbage"]
    if key == "Directory":
        return ["@a_file", "/proc/hysteron_fuzz/out", "d" * 300, ""]
    if re.search(r"[a-zA-Z]\w*\s*\(|[-+*/^]", value) or re.fullmatch(r"[txyz]", value):
        return EXPRESSIONS + ["nan", ""]
    return STRINGS


def family(kind):
    if kind == "fault":
        return "faults"
    return "inconsistent" if kind in ("conflict", "locking", "memory", "mesh") else "syntax"


def all_mutations(scenes, n_mesh_scenes=0):
    """Every mutation, in a fixed order: (scene index, kind, detail). The last
    @p n_mesh_scenes scenes only get damaged meshes."""
    out = []
    for s, scene in enumerate(scenes):
        if s >= len(scenes) - n_mesh_scenes:
            out += consistency.mutations(s, scene, mesh_scene=True)
            continue
        out += consistency.mutations(s, scene)
        out += faults.mutations(s, scene)
        for i, (line, section, key, value) in enumerate(scene.entries):
            for new in value_mutations(key, value):
                out.append((s, "value", [i, new]))
            out.append((s, "duplicate", [i]))
        for k in range(len(scene.ends)):
            out.append((s, "drop end", [k]))
        for k in range(len(scene.subsections)):
            out.append((s, "unknown entry", [k]))
            out.append((s, "unknown subsection", [k]))
        for kind in ["extra end", "self include", "include missing", "include directory",
                     "include binary", "crlf", "bom", "nul byte", "invalid utf-8", "empty file",
                     "comment only", "long line", "deep nesting", "resume fresh",
                     "file twice"]:
            out.append((s, kind, []))
        for cut in range(1, 6):
            out.append((s, "truncate", [cut / 6]))
    return out


def make_input_file(kind, directory):
    """An input file of the given kind in @p directory; its name."""
    name = {"@missing": "missing.msh", "@directory": "a_directory", "@binary": "binary.msh",
            "@empty": "empty.msh", "@huge": "huge.msh", "@garbage": "garbage.msh",
            "@a_file": "a_file"}[kind]
    path = os.path.join(directory, name)
    if kind == "@directory":
        os.mkdir(path)
    elif kind == "@binary":
        with open(path, "wb") as f:
            rng = random.Random(7)
            f.write(bytes(rng.randrange(256) for _ in range(65536)))
    elif kind == "@empty":
        open(path, "w").close()
    elif kind == "@huge":
        with open(path, "wb") as f:
            f.write(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n99999999999\n")
            f.truncate(200 * 1024 * 1024)
    elif kind == "@garbage":
        with open(path, "w") as f:
            f.write("this is not a mesh\n" * 100 + "$Nodes\n3\n1 0 0\n")
    elif kind == "@a_file":
        with open(path, "w") as f:
            f.write("a file where a directory should be\n")
    return name


def build(scene, kind, detail, workdir):
    """Write the mutated scene into @p workdir; the command-line arguments and a label."""
    lines = list(scene.lines)
    prm = "scene.prm"
    args = ["--quiet", prm]
    label = kind
    if kind == "value":
        i, new = detail
        line, section, key, value = scene.entries[i]
        if new.startswith("@"):
            new = make_input_file(new, workdir)
        indent = lines[line][:len(lines[line]) - len(lines[line].lstrip())]
        lines[line] = f"{indent}set {key} = {new}"
        label = f"{section}/{key} = {new[:40]!r}" + ("..." if len(new) > 40 else "")
    elif kind == "duplicate":
        line, section, key, value = scene.entries[detail[0]]
        lines.insert(line + 1, lines[line])
        label = f"duplicate {section}/{key}"
    elif kind == "drop end":
        del lines[scene.ends[detail[0]]]
    elif kind == "extra end":
        lines.append("end")
    elif kind == "unknown entry":
        lines.insert(scene.subsections[detail[0]] + 1, "  set Unknown fuzz entry = 1")
    elif kind == "unknown subsection":
        lines.insert(scene.subsections[detail[0]] + 1, "  subsection Unknown fuzz\n  end")
    elif kind == "self include":
        lines.insert(0, f"include {prm}")
    elif kind == "include missing":
        lines.insert(0, "include no_such_file.prm")
    elif kind == "include directory":
        os.mkdir(os.path.join(workdir, "a_directory"))
        lines.insert(0, "include a_directory")
    elif kind == "include binary":
        lines.insert(0, "include " + make_input_file("@binary", workdir))
    elif kind == "deep nesting":
        lines = ["subsection Deep"] * 2000 + ["end"] * 2000 + lines
    elif kind == "long line":
        lines.insert(0, "# " + "y" * (1 << 20))
    elif kind == "empty file":
        lines = []
    elif kind == "comment only":
        lines = ["# nothing but a comment"]
    elif kind == "resume fresh":
        args = ["--quiet", "--resume", prm]
    elif kind == "file twice":
        args = ["--quiet", prm, prm]
    elif family(kind) == "inconsistent":
        label = consistency.build(scene, kind, detail, lines, workdir)
    text = "\n".join(lines)
    data = text.encode("utf-8")
    if kind == "crlf":
        data = text.replace("\n", "\r\n").encode("utf-8")
    elif kind == "bom":
        data = b"\xef\xbb\xbf" + data
    elif kind == "nul byte":
        data = data[:len(data) // 2] + b"\0" + data[len(data) // 2:]
    elif kind == "invalid utf-8":
        data = data[:len(data) // 3] + b"\xff\xfe\xc3" + data[len(data) // 3:]
    elif kind == "truncate":
        data = data[:int(len(data) * detail[0])]
        label = f"truncate at {detail[0]:.2f}"
    with open(os.path.join(workdir, prm), "wb") as f:
        f.write(data)
    # Input files the scene reads, relative to the .prm.
    for name in scene.inputs:
        source = os.path.join(os.path.dirname(scene.path), name)
        target = os.path.join(workdir, name)
        if os.path.isfile(source) and not os.path.exists(target):
            os.makedirs(os.path.dirname(target) or workdir, exist_ok=True)
            shutil.copy(source, target)
    return args, label


def listing(directory):
    out = set()
    for root, dirs, files in os.walk(directory):
        for name in dirs + files:
            out.add(os.path.relpath(os.path.join(root, name), directory))
    return out


def non_finite_tables(directory, before):
    bad = []
    for name in sorted(listing(directory) - before):
        path = os.path.join(directory, name)
        if name.endswith(".csv") and os.path.isfile(path):
            with open(path, errors="replace") as f:
                next(f, None)
                for row, line in enumerate(f):
                    if re.search(r"(^|,)\s*[-+]?(nan|inf)", line, re.I):
                        bad.append(f"{name}:{row + 2}")
                        break
    return bad


def launch(command, cwd, env, limit):
    """Run @p command in its own session; (status or None after @p limit s, stdout, stderr,
    seconds)."""
    start = time.monotonic()
    proc = subprocess.Popen(command, cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=limit)
        status = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        status = None
    return (status, out.decode("utf-8", "replace"), err.decode("utf-8", "replace"),
            time.monotonic() - start)


def run_fault(hysteron, scene, index, detail, workdir, limit, mpiexec):
    """One fault of tests/fuzz/faults.py: several runs in @p workdir."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    env.pop("HYSTERON_TEST_SIGNAL", None)
    total = [0.0]

    def write_scene(lines, directory=workdir):
        with open(os.path.join(directory, "scene.prm"), "w") as f:
            f.write("\n".join(lines))

    def execute(args, signal_spec, cwd=workdir, ranks=1, kill_rank=None, stdout=False):
        run_env = dict(env)
        if signal_spec:
            run_env["HYSTERON_TEST_SIGNAL"] = signal_spec
        command = [hysteron] + args
        if ranks > 1:
            rank, step = kill_rank
            script = (f'if [ "$OMPI_COMM_WORLD_RANK" = {rank} ]; then '
                      f'export HYSTERON_TEST_SIGNAL=SIGKILL@{step}; fi; exec "$@"')
            command = [mpiexec, "-np", str(ranks), "sh", "-c", script, "sh"] + command
        status, out, err, seconds = launch(command, cwd, run_env, limit)
        total[0] += seconds
        return status, (out if stdout else err), seconds

    label, kind, problems, status, err = faults.run(hysteron, scene, detail, workdir,
                                                    write_scene, execute, mpiexec)
    if any(n.endswith(".tmp") for n in listing(workdir)):
        problems.append("a *.tmp is left")
    bad = non_finite_tables(workdir, set())
    if bad:
        problems.append("non-finite values in a table: " + ", ".join(bad[:3]))
    if status is not None and status < 0 and kind != "not applicable":
        problems.append(f"killed by signal {-status}")
    if status == 3:
        problems.append("exit status 3 (an internal error)")
    message = next((l for l in err.splitlines() if "error:" in l), err.strip()[-300:])
    return {"index": index, "scene": scene.name, "family": "faults", "mutation": label,
            "status": status, "seconds": round(total[0], 2), "message": message[:400],
            "class": "not applicable" if kind == "not applicable" else
            "hang" if kind == "hang" else "fault", "problems": problems}


def run_one(hysteron, scenes, index, mutation, root, limit, steps, mpiexec=None):
    s, kind, detail = mutation
    scene = scenes[s]
    workdir = os.path.join(root, f"{index:05d}")
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    if kind == "fault":
        result = run_fault(hysteron, scene, index, detail, workdir, limit, mpiexec)
        if not result["problems"]:
            shutil.rmtree(workdir, ignore_errors=True)
        return result
    args, label = build(scene, kind, detail, workdir)
    before = listing(workdir)
    env = dict(os.environ, HYSTERON_TEST_SIGNAL=f"SIGTERM@{steps}")
    status, _, err, seconds = launch([hysteron] + args, workdir, env, limit)
    message = next((l for l in err.splitlines() if "error:" in l), err.strip()[-300:])
    result = {"index": index, "scene": scene.name, "family": family(kind), "mutation": label,
              "status": status, "seconds": round(seconds, 2), "message": message[:400],
              "problems": []}
    problems = result["problems"]
    if family(kind) == "inconsistent":
        problems += consistency.expectation(scene, kind, detail, status, err, seconds)
    if kind == "mesh" and status in (0, 4) and not problems:
        # A repaired mesh must give the undamaged mesh's results.
        reference = os.path.join(workdir, "reference")
        os.makedirs(reference)
        build(scene, "as is", [], reference)
        status_ref, _, _, _ = launch([hysteron] + args, reference, env, limit)
        output = consistency.output_directory(scene)
        if status_ref == status:
            problems += ["the repaired mesh's results differ: " + d for d in
                         consistency.same_tables(os.path.join(workdir, output),
                                                 os.path.join(reference, output))][:1]
        shutil.rmtree(reference, ignore_errors=True)
    after = listing(workdir)
    if status is None:
        result["class"] = "hang"
        problems.append(f"no end within {limit} s")
    elif status < 0:
        result["class"] = "crash"
        problems.append(f"killed by signal {-status}")
    elif status not in (0, 1, 2, 4):
        result["class"] = "crash"
        problems.append(f"exit status {status}")
    elif status == 1:
        result["class"] = "refused"
        if "error:" not in err:
            problems.append("exit 1 without an error message")
        elif not PATH_IN_MESSAGE.search(message) and (kind != "value" or
                                                      scene.entries[detail[0]][2] not in message):
            problems.append("the error names no parameter path")
        if after != before:
            problems.append("exit 1 left files: " + ", ".join(sorted(after - before))[:200])
    else:
        result["class"] = {0: "accepted", 2: "run failed", 4: "stopped at step budget"}[status]
        tmp = [n for n in after if n.endswith(".tmp")]
        if tmp:
            problems.append("left " + ", ".join(tmp[:3]))
        if status in (0, 4):
            bad = non_finite_tables(workdir, before)
            if bad:
                problems.append("non-finite values in an accepted run: " + ", ".join(bad[:3]))
        if status == 2 and "error:" not in err:
            problems.append("exit 2 without an error message")
    if not problems:
        shutil.rmtree(workdir, ignore_errors=True)
    return result


FAMILIES = [("syntax", "syntax, values, files, command line"),
            ("inconsistent", "physically inconsistent inputs"),
            ("faults", "faults during a run")]


def report(results, args, seconds, path):
    classes = ["refused", "accepted", "run failed", "stopped at step budget", "fault",
               "not applicable", "crash", "hang"]
    lines = [
        "| family | tried | refused cleanly (exit 1) | accepted (exit 0) | run failed cleanly "
        "(exit 2) | stopped at the step budget (exit 4) | faults handled | not applicable | "
        "crashes | hangs | rule violations |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, title in FAMILIES:
        rs = [r for r in results if r["family"] == name]
        if not rs:
            continue
        count = {c: sum(r["class"] == c for r in rs) for c in classes}
        bad = [r for r in rs if r["problems"]]
        clean = lambda c: count[c] - sum(r["class"] == c for r in bad)
        lines.append(f"| {title} | {len(rs)} | {clean('refused')} | {clean('accepted')} | "
                     f"{clean('run failed')} | {clean('stopped at step budget')} | "
                     f"{clean('fault')} | {count['not applicable']} | {count['crash']} | "
                     f"{count['hang']} | {len(bad)} |")
    failed = [r for r in results if r["problems"]]
    table = "\n".join(lines)
    print(table)
    print(f"\n{len(results)} runs, seed {args.seed}, {seconds:.0f} s")
    for r in failed:
        print(f"FAIL {r['index']:5d} {r['scene']}: {r['mutation']}: status {r['status']}, "
              f"{r['seconds']} s: {'; '.join(r['problems'])}\n      {r['message']}")
    if path:
        begin, end = "<!-- fuzz table begin -->", "<!-- fuzz table end -->"
        with open(path) as f:
            text = f.read()
        scenes = len(set(r["scene"] for r in results))
        body = (f"{begin}\n{table}\n\n`tests/fuzz/fuzz.py --count {args.count} --inconsistent "
                f"{args.inconsistent} --faults {args.faults} --seed {args.seed} --steps "
                f"{args.steps} --limit {args.limit}`: {len(results)} cases of {scenes} scenes in "
                f"{seconds / 60:.0f} min ({args.jobs} at a time).\n{end}")
        text = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda m: body, text, flags=re.S)
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    return not failed


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--hysteron", required=True)
    parser.add_argument("--scene", action="append", default=[],
                        help="scenes to mutate (default: every prm/*.prm)")
    parser.add_argument("--mesh-scene", action="append", default=[],
                        help="scenes with a Gmsh mesh to damage (default: tests/fem's)")
    parser.add_argument("--count", type=int, default=40, help="syntax mutations to run")
    parser.add_argument("--inconsistent", default="all",
                        help="inconsistent inputs to run: a number or 'all'")
    parser.add_argument("--faults", default="all", help="faults to run: a number or 'all'")
    parser.add_argument("--mpiexec", default=shutil.which("mpirun"),
                        help="MPI launcher for the killed-rank faults")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--limit", type=float, default=60, help="seconds per run")
    parser.add_argument("--steps", type=int, default=100, help="step budget per run")
    parser.add_argument("--workdir", default="fuzz_runs")
    parser.add_argument("--report", help="update the table in this Markdown file")
    parser.add_argument("--json", help="write every run's result here")
    parser.add_argument("--only", type=int, nargs="*", help="run only these mutation indices")
    args = parser.parse_args()

    paths = args.scene or sorted(
        os.path.join(here, "..", "..", "prm", n) for n in os.listdir(os.path.join(here, "..", "..", "prm"))
        if n.endswith(".prm"))
    tests = os.path.join(here, "..")
    mesh_paths = args.mesh_scene or [os.path.join(tests, "fem", n) for n in
                                     ("gmsh_mesh.prm", "simplex_gmsh_triangles.prm",
                                      "physical_groups_tension.prm")]
    scenes = [Scene(os.path.abspath(p)) for p in paths + mesh_paths]
    mutations = all_mutations(scenes, len(mesh_paths))
    chosen = []
    for name, count in (("syntax", args.count), ("inconsistent", args.inconsistent),
                        ("faults", args.faults)):
        order = [i for i, m in enumerate(mutations) if family(m[1]) == name]
        random.Random(args.seed).shuffle(order)
        chosen += order if count == "all" else order[:int(count)]
    if args.only is not None:
        chosen = args.only
    hysteron = os.path.abspath(args.hysteron)
    root = os.path.abspath(args.workdir)
    os.makedirs(root, exist_ok=True)
    print(f"{len(mutations)} cases of {len(scenes)} scenes ("
          + ", ".join(f"{sum(family(m[1]) == n for m in mutations)} {n}" for n, _ in FAMILIES)
          + f"); running {len(chosen)}", flush=True)

    start = time.monotonic()
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run_one, hysteron, scenes, i, mutations[i], root, args.limit,
                               args.steps, args.mpiexec) for i in chosen]
        for done, future in enumerate(concurrent.futures.as_completed(futures), 1):
            r = future.result()
            results.append(r)
            if r["problems"]:
                print(f"  [{done}/{len(chosen)}] {r['scene']}: {r['mutation']}: "
                      f"{'; '.join(r['problems'])}", flush=True)
            elif done % 50 == 0:
                print(f"  [{done}/{len(chosen)}] {time.monotonic() - start:.0f} s", flush=True)
    results.sort(key=lambda r: r["index"])
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    ok = report(results, args, time.monotonic() - start, args.report)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
