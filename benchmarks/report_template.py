"""Fill a Markdown template whose measured values are `{{ expression }}` fields.

Shared by benchmarks/make_report.py (doc/benchmarks.md) and the verification report: the
template holds no measured number, only expressions evaluated against a namespace the report
script provides. A field that cannot be evaluated stops the script (SystemExit) before the
report is written, so a report never mixes fresh and stale numbers. `write_atomically` writes
to a temporary name and renames.
"""
import os
import re


def fill(template, namespace, name="report"):
    """Replace every {{ expression }} by str(eval(expression, namespace))."""
    def field(match):
        try:
            return str(eval(match.group(1), {"__builtins__": {}}, namespace))
        except Exception as e:  # noqa: BLE001 (any failure of a field stops the report)
            raise SystemExit(f"{name}: template field {{{{{match.group(1).strip()}}}}}: "
                             f"{type(e).__name__}: {e}")

    return re.sub(r"\{\{(.*?)\}\}", field, template, flags=re.S)


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
