"""Faults during a run, for tests/fuzz/fuzz.py. Each starts from the shipped scene stopped by
SIGTERM after 3 steps (exit 4, a checkpoint), then:

  flip bit       one bit of a file of the checkpoint flipped (each file in turn)
  truncate       the checkpoint's largest file cut to half
  damaged info   one bit of the checkpoint's info.txt flipped
  edited input   the parameter file edited (Young's modulus 1 % higher) before --resume
  stale          a checkpoint of that run put back beside a newer run's tables and
                 checkpoint, whose Young's modulus differs
  full disk      a file of the run (table, VTU, record, manifest) behind /dev/full in a new
                 run: its write fails with ENOSPC
  killed rank    on 2 MPI ranks with a checkpoint every step, rank 1 killed (SIGKILL) at
                 step 4; then hysteron --status, and --resume on 1 rank

The rules: a damaged, stale or mismatched checkpoint is never resumed silently: --resume
refuses (exit 1, naming --resume or the changed entry) and leaves every table as it was, or
resumes from an older intact checkpoint with a warning; a full disk is a run-time error
(exit 2; exit 1 before the run) naming the file and "No space left on device", with no *.tmp
left; a killed rank ends the job within the time limit, --status does not say "running"
and the checkpoint before the kill resumes on another number of ranks.
"""
import hashlib
import os
import random
import shutil
import subprocess

KINDS = ["flip bit", "truncate", "damaged info", "edited input", "stale", "full disk",
         "killed rank"]
FLIPS = 3
DISKS = 3


def mutations(s, scene):
    out = []
    for kind in KINDS:
        count = FLIPS if kind == "flip bit" else DISKS if kind == "full disk" else 1
        for pick in range(count):
            out.append((s, "fault", [kind, pick]))
    return out


def _output_directory(scene, workdir):
    value = next((v for _, section, key, v in scene.entries
                  if section == "Output" and key == "Directory"), "output")
    return os.path.join(workdir, value or "output")


def _files(directory):
    out = []
    for root, dirs, files in os.walk(directory):
        for name in files:
            out.append(os.path.relpath(os.path.join(root, name), directory))
    return sorted(out)


def _tables(directory):
    """Digest of every CSV table under @p directory."""
    out = {}
    for name in _files(directory):
        if name.endswith(".csv"):
            with open(os.path.join(directory, name), "rb") as f:
                out[name] = hashlib.sha256(f.read()).hexdigest()
    return out


def _table_bytes(directory):
    out = {}
    for name in _files(directory):
        if name.endswith(".csv"):
            with open(os.path.join(directory, name), "rb") as f:
                out[name] = f.read()
    return out


def _checkpoints(directory):
    out = []
    for root, dirs, files in os.walk(directory):
        for name in dirs:
            if name.startswith("checkpoint-") and not name.endswith(".tmp"):
                out.append(os.path.join(root, name))
    return sorted(out, key=lambda p: os.path.basename(p))


def _edit_young(lines, scene, factor):
    for line, section, key, value in scene.entries:
        if key == "Young's modulus":
            try:
                new = float(value) * factor
            except ValueError:
                continue
            indent = lines[line][:len(lines[line]) - len(lines[line].lstrip())]
            lines[line] = f"{indent}set {key} = {new!r}"
            return True
    return False


def run(hysteron, scene, detail, workdir, write_scene, execute, mpiexec):
    """Carry out one fault in @p workdir. write_scene(lines) writes the scene file;
    execute(args, env_signal, ranks=1) runs hysteron -> (status, stderr, seconds).
    Returns (label, class, problems, last status, message)."""
    kind, pick = detail
    label = f"{kind} {pick}" if kind in ("flip bit", "full disk") else kind
    output = _output_directory(scene, workdir)
    problems = []
    lines = list(scene.lines)

    if kind == "full disk":
        # The files a run writes, from a first run in a directory of its own.
        probe = os.path.join(workdir, "probe")
        os.makedirs(probe)
        write_scene(lines, probe)
        status, err, _ = execute(["--quiet", "scene.prm"], "SIGTERM@3", cwd=probe)
        written = [n for n in _files(_output_directory(scene, probe))
                   if "checkpoint-" not in n and not n.startswith(".hysteron")]
        shutil.rmtree(probe)
        if status not in (0, 4) or not written:
            return label, "not applicable", [], status, err
        name = written[(pick * 5 + 1) % len(written)]
        label = f"full disk at {name}"
        write_scene(lines, workdir)
        os.makedirs(os.path.dirname(os.path.join(output, name)), exist_ok=True)
        os.symlink("/dev/full", os.path.join(output, name + ".tmp"))
        before = set(_files(workdir))
        status, err, _ = execute(["--quiet", "scene.prm"], "SIGTERM@3")
        base = os.path.basename(name)
        if status not in (1, 2):
            problems.append(f"a write to a full disk ended with exit {status}")
        elif not ("No space left on device" in err and base in err):
            problems.append(f"the failure does not name {base} and ENOSPC")
        left = set(_files(workdir))
        if any(n.endswith(".tmp") for n in left):
            problems.append("a *.tmp is left")
        if status == 1 and left - before:
            problems.append("exit 1 left files")
        return label, "fault", problems, status, err

    write_scene(lines, workdir)
    if kind == "killed rank":
        if not mpiexec:
            return label, "not applicable", [], None, "no MPI launcher"
        lines.extend(["subsection Checkpoint", "  set Interval = 1", "end"])
        write_scene(lines, workdir)
        status, err, seconds = execute(["--quiet", "scene.prm"], None, ranks=2, kill_rank=(1, 4))
        if status is None:
            problems.append("the job did not end after a rank was killed")
            return label, "hang", problems, status, err
        if status == 0:
            return label, "not applicable", [], status, err
        if not _checkpoints(output):
            return label, "not applicable", [], status, err
        s2, state, _ = execute(["--status", os.path.relpath(output, workdir)], None, stdout=True)
        if state.strip().lower().startswith("running"):
            problems.append(f"--status after the kill: {state.strip()[:200]}")
        status, err, _ = execute(["--quiet", "--resume", "scene.prm"], "SIGTERM@7")
        if status not in (0, 4):
            problems.append(f"the checkpoint before the kill did not resume on 1 rank (exit {status})")
        return label, "fault", problems, status, err

    status, err, _ = execute(["--quiet", "scene.prm"], "SIGTERM@3")
    checkpoints = _checkpoints(output)
    if status != 4 or not checkpoints:
        return label, "not applicable", [], status, err
    newest = checkpoints[-1]
    if kind in ("flip bit", "truncate", "damaged info"):
        files = [n for n in _files(newest) if n != "info.txt"]
        if kind == "damaged info":
            name = "info.txt"
        elif kind == "truncate":
            name = max(files, key=lambda n: os.path.getsize(os.path.join(newest, n)))
        else:
            name = files[pick % len(files)]
        path = os.path.join(newest, name)
        with open(path, "rb") as f:
            data = bytearray(f.read())
        if kind == "truncate":
            data = data[:len(data) // 2]
        elif data:
            offset = random.Random(pick * 31 + len(data)).randrange(len(data))
            data[offset] ^= 1 << (pick % 8)
        with open(path, "wb") as f:
            f.write(bytes(data))
        label = f"{kind} of {os.path.basename(newest)}/{name}"
    elif kind == "edited input":
        if not _edit_young(lines, scene, 1.01):
            return label, "not applicable", [], status, err
        write_scene(lines, workdir)
    elif kind == "stale":
        aside = os.path.join(workdir, "aside")
        shutil.copytree(newest, aside)
        base = os.path.dirname(newest)
        own = _table_bytes(base)
        with open(os.path.join(newest, "info.txt")) as f:
            counted = {w[3]: int(w[1]) for w in (l.split(" ", 3) for l in f.read().splitlines())
                       if w[0] == "table" and len(w) == 4}
        edited = list(lines)
        if not _edit_young(edited, scene, 1.01):
            return label, "not applicable", [], status, err
        write_scene(edited, workdir)
        status, err, _ = execute(["--quiet", "scene.prm"], "SIGTERM@2")
        if status != 4:
            return label, "not applicable", [], status, err
        shutil.copytree(aside, newest)
        shutil.rmtree(aside)
        write_scene(lines, workdir)
    tables = _tables(output)
    status, err, _ = execute(["--quiet", "--resume", "scene.prm"], "SIGTERM@6")
    if status == 1 and "does not write checkpoints" in err:
        return label, "not applicable", [], status, err  # a comparison starts anew
    if status in (0, 4):
        if kind != "stale" and not any(w in err for w in ("skipping", "resuming from",
                                                          "newer checkpoint")):
            problems.append("a damaged or mismatched checkpoint was resumed without a word")
        if kind == "edited input":
            problems.append("a resume continued tables of another run")
        if kind == "stale":
            # Accepted only where the other run's tables begin with this run's rows up to
            # the checkpoint (rows before the parameters made a difference).
            now = _table_bytes(base)
            if any(now.get(name, b"")[:n] != own.get(name, b"")[:n] for name, n in counted.items()):
                problems.append("a resume continued tables of another run")
    elif status == 1:
        if _tables(output) != tables:
            problems.append("the refused resume changed the tables")
        if kind == "edited input" and "Young's modulus" not in err and "scene.prm" not in err:
            problems.append("the refusal does not name the edited entry")
    elif status is not None and status >= 0:
        problems.append(f"--resume ended with exit {status}")
    return label, "fault", problems, status, err
