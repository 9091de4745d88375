#!/usr/bin/env python3
"""The particle VTU on a moving grid shows the points where they are: the free block of
moving_grid_follow_translation.prm (velocity (1, 0.5) m/s, a grid that follows it) written at
t = 0, about 1 and 2 s (the TIME of each file). In every output each point's position minus its displacement is its place in
the initial block [-0.1, 0.1]^2, and the displacement is v t (to 1e-4 m: float32 and the six digits of TIME). The handler
keeps the points in the frame of the set-up's grid internally; a VTU written from that frame
would put the block back at the origin.

Usage: moving_grid_vtu.py HYSTERON WORKDIR
"""
import base64
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

hysteron, work = sys.argv[1:3]
here = os.path.dirname(os.path.abspath(__file__))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
text = open(os.path.join(here, "moving_grid_follow_translation.prm")).read()
text = text.replace("set Interval = 0.5", "set Interval = 1")
with open(os.path.join(work, "scene.prm"), "w") as f:
    f.write(text)
p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=work, capture_output=True, text=True,
                   env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
if p.returncode != 0:
    sys.exit(f"exit {p.returncode}: {p.stderr[-2000:]}")


def float_arrays(path):
    """Name -> the values of every Float32 DataArray of a zlib-compressed binary VTU."""
    result = {}
    t = open(path).read()
    for m in re.finditer(r'<DataArray type="Float32"( Name="([^"]*)")? NumberOfComponents="3" format="binary">\s*(.*?)\s*</DataArray>', t, re.S):
        data = m.group(3)
        header = base64.b64decode(data[:24])  # 4 UInt32: blocks, block size, last block, compressed size
        blocks, _, _, size = struct.unpack("<4I", header)
        if blocks != 1:
            raise SystemExit(f"{path}: {blocks} compressed blocks")
        raw = zlib.decompress(base64.b64decode(data[24:])[:size])
        result[m.group(2) or "points"] = struct.unpack("<%df" % (len(raw) // 4), raw)
    return result


failures = []
for k in range(3):
    path = os.path.join(work, "output", f"particles-{k:05d}.vtu")
    t = float(re.search(r'Name="TIME" NumberOfTuples="1" format="ascii">([^<]+)<', open(path).read()).group(1))
    arrays = float_arrays(path)
    points, u = arrays["points"], arrays["displacement"]
    if len(points) != len(u) or len(points) < 3:
        failures.append(f"t = {t}: {len(points)} point coordinates, {len(u)} displacements")
        continue
    for i in range(0, len(points), 3):
        x0 = [points[i + d] - u[i + d] for d in range(2)]
        if not all(-0.1 - 1e-5 < c < 0.1 + 1e-5 for c in x0):
            failures.append(f"t = {t}: point {i // 3} at {points[i:i + 2]} started at {x0}, outside the block")
            break
        if abs(u[i] - t) > 1e-4 or abs(u[i + 1] - 0.5 * t) > 1e-4:
            failures.append(f"t = {t}: point {i // 3} has the displacement {u[i:i + 2]}")
            break
if failures:
    print("FAILED:\n  " + "\n  ".join(failures))
    sys.exit(1)
print(f"passed: 3 outputs, {len(points) // 3} points each, where they are")
