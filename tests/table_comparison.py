"""The CSV tables of two output directories compared column by column (shared by the tests that
run one scene two ways: tests/rbsn/incremental_assembly.py, tests/fem/threads.py)."""
import csv
import os


def compare_tables(name, a, b, relative, floor, exact=False):
    """Every CSV table of directory a against b; returns the failures (a list of strings).

    exact: the files must be identical. Otherwise the tables must have the same rows and columns,
    and every numeric value must agree to `relative` times its column's largest value, or to
    `floor` times the table's largest value (for columns that are round-off themselves)."""
    failures = []
    tables = sorted(f for f in os.listdir(a) if f.endswith(".csv"))
    if not tables or tables != sorted(f for f in os.listdir(b) if f.endswith(".csv")):
        return [f"{name}: tables {tables} in {a} against those in {b}"]
    for table in tables:
        ra = list(csv.reader(open(os.path.join(a, table))))
        rb = list(csv.reader(open(os.path.join(b, table))))
        if exact:
            if ra != rb:
                failures.append(f"{name}: {table} differs")
            continue
        if len(ra) != len(rb) or ra[:1] != rb[:1]:
            failures.append(f"{name}: {table}: {len(ra)} rows against {len(rb)} (or other columns)")
            continue
        columns = []
        for j, column in enumerate(ra[0]):
            try:
                columns.append((column, [float(r[j]) for r in ra[1:]], [float(r[j]) for r in rb[1:]]))
            except ValueError:
                continue
        largest = max([abs(x) for _, xa, _ in columns for x in xa] + [1e-300])
        for column, xa, xb in columns:
            scale = max([abs(x) for x in xa] + [0.0])
            for i, (x, y) in enumerate(zip(xa, xb)):
                if abs(x - y) > max(relative * scale, floor * largest):
                    failures.append(f"{name}: {table}: column {column}, row {i + 1}: {x!r} vs {y!r}")
                    break
    return failures
