#!/usr/bin/env python3
"""A damaged checkpoint, a changed input or a cut table never resumes silently.

    checkpoint_damage.py --hysteron EXE --workdir DIR [--mpiexec M] [--np N]
                         [--interval K] scene.prm [input[=source] ...]

The scene (checkpoints every k steps, all kept) runs uninterrupted (the reference) and
again, killed (SIGKILL) after step ~0.8 of its steps with several checkpoints written. Copies
of the killed run are then damaged and resumed with `hysteron --resume`:

* one bit flipped in a file of the newest checkpoint (several seeded positions: each file of
  the checkpoint once), or a file of it cut short: the resume warns that the newest
  checkpoint is not usable, resumes from the next older one and ends with the reference's
  tables (1e-12 of each column's scale);
* a bit flipped in every checkpoint: refused (exit 1, "no usable checkpoint"), no table
  changed;
* an input file (the scene's inputs given after the .prm: a mesh, an amplitude table)
  edited since the checkpoints: refused, naming the file, no table changed;
* a time table cut shorter than it was at the newest checkpoint (as a machine crash can leave
  it): that checkpoint is not used, an older one whose rows the table still holds is, and the
  tables equal the reference's with no NUL byte; cut shorter than at every checkpoint:
  refused, no table changed.
"""
import argparse
import os
import random
import re
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from resume_test import run, tables, read_table  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from run_prm_test import compare_csv  # noqa: E402


def checkpoints(directory):
    out = os.path.join(directory, "output")
    found = sorted(d for d in os.listdir(out) if re.fullmatch(r"checkpoint-\d+", d))
    return [os.path.join(out, d) for d in found]


def snapshot(directory):
    """The bytes of every table (to tell that a refused resume changed nothing)."""
    result = {}
    for relative, path in tables(directory).items():
        with open(path, "rb") as f:
            result[relative] = f.read()
    return result


def flip_bit(path, rng):
    with open(path, "r+b") as f:
        data = bytearray(f.read())
        position = rng.randrange(len(data))
        data[position] ^= 1 << rng.randrange(8)
        f.seek(0)
        f.write(data)
    return position


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--interval", type=int, default=0,
                    help="append a Checkpoint subsection: a checkpoint every this many steps, all kept")
    ap.add_argument("--flips-only", action="store_true",
                    help="only the damaged files of the newest checkpoint (the other cases are the "
                         "driver's, the same for every method)")
    ap.add_argument("prm")
    ap.add_argument("inputs", nargs="*")
    args = ap.parse_args()

    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    env.pop("HYSTERON_TEST_SIGNAL", None)
    launcher = [args.mpiexec, "-np", str(args.np)] if args.np > 1 else []
    # A fixture may be named *.scene (not a scene test of its own): it runs as *.prm.
    name = os.path.splitext(os.path.basename(args.prm))[0] + ".prm"
    source = os.path.dirname(os.path.abspath(args.prm))
    failures = []

    def prepare(directory):
        shutil.rmtree(directory, ignore_errors=True)
        os.makedirs(directory)
        shutil.copy(args.prm, os.path.join(directory, name))
        if args.interval:
            with open(os.path.join(directory, name), "a") as f:
                f.write(f"\nsubsection Checkpoint\n  set Interval = {args.interval}\n"
                        "  set Number kept = 100\nend\n")
        for item in args.inputs:
            target, _, origin = item.partition("=")
            shutil.copy(os.path.join(source, origin or target), os.path.join(directory, target))

    reference = os.path.join(args.workdir, "reference")
    prepare(reference)
    code, out, err = run(launcher + [args.hysteron, name], reference, env)
    m = re.search(r"(\d+) steps", out)
    if code != 0 or not m:
        print(out[-2000:], err[-2000:])
        print("FAILED: the reference run")
        return 1
    n_steps = int(m.group(1))

    killed = os.path.join(args.workdir, "killed")
    prepare(killed)
    at = int(0.8 * n_steps) + 1
    code, out, err = run(launcher + [args.hysteron, "--quiet", name], killed,
                         dict(env, HYSTERON_TEST_SIGNAL=f"SIGKILL@{at}"))
    saved = checkpoints(killed)
    print(f"{name}: {n_steps} steps, killed after step {at} with {len(saved)} checkpoints")
    if len(saved) < 3:
        print("FAILED: the scene must leave at least 3 checkpoints")
        return 1
    expected = tables(reference)

    def resume_case(label, damage, refused=None):
        """Copy the killed run, damage it, resume: @p refused is None (must end as the
        reference) or a regular expression the refusal's message must match."""
        directory = os.path.join(args.workdir, label)
        shutil.rmtree(directory, ignore_errors=True)
        shutil.copytree(killed, directory)
        note = damage(directory)
        before = snapshot(directory)
        code, out, err = run(launcher + [args.hysteron, "--quiet", "--resume", name], directory, env)
        problems = []
        if refused is not None:
            if code != 1:
                problems.append(f"exit status {code}, expected 1")
            if not re.search(refused, err):
                problems.append(f"the message does not say /{refused}/: {err.strip()[-400:]!r}")
            if snapshot(directory) != before:
                problems.append("a refused resume changed a table")
        else:
            if code != 0:
                problems.append(f"exit status {code}: {err.strip()[-400:]!r}")
            elif not re.search(r"not usable", err):
                problems.append(f"no warning that the newest checkpoint is not usable: {err.strip()[-300:]!r}")
            got = tables(directory)
            for relative in sorted(expected):
                path = got.get(relative)
                if path is None:
                    problems.append(f"{relative} missing")
                    continue
                with open(path, "rb") as f:
                    if b"\0" in f.read():
                        problems.append(f"{relative} holds NUL bytes")
                        continue
                problem = compare_csv(expected[relative], path, (1e-12, 0.0))
                if problem:
                    problems.append(f"{relative}: {problem}")
        print(f"{label} ({note}): {'ok' if not problems else '; '.join(problems)}")
        failures.extend(f"{label}: {p}" for p in problems)

    rng = random.Random(2026)
    newest_files = sorted(os.listdir(saved[-1]))
    for file in newest_files:
        def flip(directory, file=file):
            path = os.path.join(checkpoints(directory)[-1], file)
            return f"bit flipped at byte {flip_bit(path, rng)} of {file}"
        resume_case(f"flip_{file}", flip)

    if args.flips_only:
        if failures:
            print("FAILED:\n  " + "\n  ".join(failures))
            return 1
        print("passed")
        return 0

    def truncate(directory):
        newest = checkpoints(directory)[-1]
        largest = max(os.listdir(newest), key=lambda f: os.path.getsize(os.path.join(newest, f)))
        path = os.path.join(newest, largest)
        os.truncate(path, os.path.getsize(path) // 2)
        return f"{largest} cut to half"
    resume_case("truncated_newest", truncate)

    def flip_all(directory):
        for c in checkpoints(directory):
            files = sorted(f for f in os.listdir(c) if os.path.getsize(os.path.join(c, f)) > 0)
            flip_bit(os.path.join(c, rng.choice(files)), rng)
        return "a bit flipped in every checkpoint"
    resume_case("all_damaged", flip_all, refused=r"no usable checkpoint")

    for item in args.inputs:
        target = item.partition("=")[0]

        def edit(directory, target=target):
            path = os.path.join(directory, target)
            with open(path) as f:
                text = f.read()
            # Change one digit so that the file still parses: a value of a table (the last
            # column's last non-zero digit), a node's coordinate of a mesh (mid-file).
            if target.endswith(".csv"):
                i = [m.start(1) for m in re.finditer(r",[ -]*([1-9])", text)][-1]
            else:
                digits = [m.start() for m in re.finditer(r"[1-9]", text)]
                i = digits[len(digits) // 2]
            with open(path, "w") as f:
                f.write(text[:i] + str(int(text[i]) % 9 + 1) + text[i + 1:])
            return f"a digit of {target} changed"
        resume_case(f"edited_{target}", edit, refused=re.escape(target) + r".* changed")

    # The longest table: cut to fewer rows than at the newest checkpoint but more than at the
    # oldest (an older checkpoint is used), and to its header only (none can be used).
    longest = max(tables(killed).values(), key=lambda p: len(read_table(p)[1]))
    relative_longest = os.path.relpath(longest, killed)

    def cut(rows):
        def damage(directory):
            path = os.path.join(directory, relative_longest)
            with open(path) as f:
                lines = f.read().splitlines(keepends=True)
            with open(path, "w") as f:
                f.writelines(lines[:1 + rows])
            return f"{relative_longest} cut to {rows} rows"
        return damage
    n_rows = len(read_table(longest)[1])
    resume_case("table_cut", cut(int(0.5 * n_rows)))
    resume_case("table_cut_to_header", cut(0), refused=r"no usable checkpoint")

    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
