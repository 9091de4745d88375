#!/usr/bin/env python3
"""One job per function and per file: no function longer than 150 lines and no file longer than
700 lines in source/ and include/.

    sizes.py [--root DIR] [--exceptions FILE]

Functions are found by matching braces after comments and literals are removed: a block that
follows a parameter list at namespace or class scope is a function, and the lambdas inside it are
part of it. A file or function that may be longer (a generated table) is named in the exceptions
file with the reason; an exception that no longer applies is an error too, so that the list
cannot go stale. Exit status 1 and the offenders listed when a limit is exceeded."""
import re, sys, pathlib

CONTROL = re.compile(r'\b(if|for|while|switch|catch|do|else|return|namespace|class|struct|enum|union)\b')

def strip(text):
    # remove comments and string/char literals, keep newlines
    out = []; i = 0; n = len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i); j = n if j < 0 else j
            i = j; continue
        if text.startswith('/*', i):
            j = text.find('*/', i + 2); j = n if j < 0 else j + 2
            out.append('\n' * text.count('\n', i, j)); i = j; continue
        if text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            if m:
                end = ')' + m.group(1) + '"'
                j = text.find(end, i); j = n if j < 0 else j + len(end)
                out.append('""' + '\n' * text.count('\n', i, j)); i = j; continue
        if c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            out.append(c + c + '\n' * text.count('\n', i, j)); i = j + 1; continue
        out.append(c); i += 1
    return ''.join(out)

def functions(path):
    text = strip(pathlib.Path(path).read_text())
    res = []
    stack = []  # (kind, start_line, name)
    line = 1; last = 0
    for i, c in enumerate(text):
        if c == '\n':
            line += 1
        elif c == '{':
            head = text[last:i]
            in_fn = any(k == 'f' for k, _, _ in stack)
            h = head.strip()
            kind = 'b'
            if not in_fn and re.search(r'\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(final)?\s*(->\s*[\w:<>,\s]+)?\s*$', h) \
               and not CONTROL.search(h.split('(')[0][-40:] if '(' in h else h):
                kind = 'f'
            elif not in_fn and re.search(r'\)\s*:\s*', h) and re.search(r'[\w>)]\s*[({]?\s*$', h) \
                    and not CONTROL.search(h.split('(')[0]):
                kind = 'f'  # constructor with initialiser list
            name = re.sub(r'\s+', ' ', h.split('\n')[-1] if h else '')[-80:]
            m = re.findall(r'([\w:~]+)\s*\(', h)
            if m: name = m[0] if kind == 'f' else name
            stack.append((kind, line, name))
            last = i + 1
        elif c == '}':
            if stack:
                kind, start, name = stack.pop()
                if kind == 'f':
                    res.append((line - start + 1, start, name))
            last = i + 1
        elif c == ';':
            last = i + 1
    return res

def main():
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default=".")
    ap.add_argument("--exceptions", default=None)
    args = ap.parse_args()
    limit_f, limit_file = 150, 700
    root = pathlib.Path(args.root)
    allowed = {}
    if args.exceptions:
        for line in open(args.exceptions):
            line = line.split("#", 1)[0].strip()
            if line:
                allowed[line] = False
    files = [p for d in ("source", "include") for p in (root / d).rglob("*") if p.suffix in (".h", ".cc")]
    bad = 0
    n_functions = 0
    for p in sorted(files):
        rel = str(p.relative_to(root))
        n = p.read_text().count("\n")
        if n > limit_file:
            if rel in allowed:
                allowed[rel] = True
            else:
                print(f"{rel}: {n} lines (at most {limit_file})"); bad += 1
        for length, start, name in functions(p):
            n_functions += 1
            key = f"{rel}:{name}"
            if length > limit_f:
                if key in allowed:
                    allowed[key] = True
                else:
                    print(f"{rel}:{start}: {name} has {length} lines (at most {limit_f})"); bad += 1
    for key, used in allowed.items():
        if not used:
            print(f"{args.exceptions}: {key} is within the limits now: remove the exception"); bad += 1
    print(f"{len(files)} files, {n_functions} functions; {bad} over the limits")
    return 1 if bad else 0


sys.exit(main())
