"""Fill a Markdown template whose measured values are `{{ expression }}` fields.

Shared by benchmarks/make_report.py (doc/benchmarks.md) and the verification report: the
template holds no measured number, only expressions evaluated against a namespace the report
script provides. A field that cannot be evaluated stops the script (SystemExit) before the
report is written, so a report never mixes fresh and stale numbers. `write_atomically` writes
to a temporary name and renames. `environment` describes machine, system, build and code.
"""
import os
import platform
import re
import subprocess


SAFE_BUILTINS = {f.__name__: f for f in (abs, all, any, len, max, min, range, round, sorted, str, sum)}


def fill(template, namespace, name="report"):
    """Replace every {{ expression }} by str(eval(expression, namespace))."""
    def field(match):
        try:
            return str(eval(match.group(1), {"__builtins__": SAFE_BUILTINS, **namespace}))
        except Exception as e:  # noqa: BLE001 (any failure of a field stops the report)
            raise SystemExit(f"{name}: template field {{{{{match.group(1).strip()}}}}}: "
                             f"{type(e).__name__}: {e}")

    return re.sub(r"\{\{(.*?)\}\}", field, template, flags=re.S)


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def environment(build, root):
    """Machine, system, build and commit of a report, as a dict of strings."""
    cpu = re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read())
    memory = re.search(r"MemTotal:\s*(\d+)", open("/proc/meminfo").read())
    cache = open(os.path.join(build, "CMakeCache.txt")).read()
    build_type = re.search(r"CMAKE_BUILD_TYPE:STRING=(.*)", cache)
    compiler = re.search(r"CMAKE_CXX_COMPILER:(?:FILEPATH|STRING)=(.*)", cache)
    try:
        compiler = subprocess.check_output([compiler.group(1), "--version"], text=True).splitlines()[0]
    except (AttributeError, OSError, subprocess.CalledProcessError):
        compiler = "unknown"
    config = "/usr/include/deal.II/base/config.h"
    dealii = re.search(r'DEAL_II_PACKAGE_VERSION "([^"]+)"', open(config).read()) if os.path.exists(config) else None

    def git(*a):
        try:
            return subprocess.check_output(["git", *a], cwd=root, text=True).strip()
        except (OSError, subprocess.CalledProcessError):
            return "unknown"

    # Changes under doc/ (the reports being written) do not make the code dirty.
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)doc")
    debian = open("/etc/debian_version").read().strip() if os.path.exists("/etc/debian_version") else "?"
    return dict(
        cpu=cpu.group(1).strip() if cpu else "unknown CPU", cores=os.cpu_count(),
        memory=f"{int(memory.group(1)) / 2**20:.0f} GiB" if memory else "?",
        os=f"Debian {debian}, {platform.system()} {platform.release()}",
        build_type=build_type.group(1) if build_type else "?", compiler=compiler,
        dealii=dealii.group(1) if dealii else "?",
        commit=git("rev-parse", "--short", "HEAD") + (" (with uncommitted changes)" if dirty else ""))
