#!/usr/bin/env python3
"""Draw an RBSN output (rbsn-NNNNN.vtu): the Voronoi cells, optionally displaced and coloured
by a cell field, and the broken facets (the line cells of the file with broken = 1) as red lines.

Usage:
  plot_rbsn_cells.py FILE.vtu|FILE.pvtu OUT.png [--field H1] [--magnify 50] [--title "..."]
                     [--xlim a b] [--ylim a b] [--label "colour bar label"]

The VTU is the file hysteron writes (inline binary arrays, base64 with a UInt64 byte count;
older ASCII files are read too; polygons: VTK type 7; facets: type 3, with the cell field broken).
Needs python3-matplotlib (Debian's /usr/bin/python3).
"""
import argparse
import base64
import re
import struct
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402


FORMATS = {"Float64": "d", "Float32": "f", "Int64": "q", "Int32": "i", "UInt8": "B"}


def decode(attributes, body):
    """The values of one DataArray: ASCII, or base64 of a UInt64 byte count and the bytes."""
    if 'format="binary"' not in attributes:
        return [float(v) for v in body.split()]
    code = FORMATS[re.search(r'type="(\w+)"', attributes).group(1)]
    raw = base64.b64decode("".join(body.split()))
    count = struct.unpack("<Q", raw[:8])[0]
    return [float(v) for v in struct.unpack("<%d%s" % (count // struct.calcsize(code), code), raw[8:8 + count])]


def read_vtu(path):
    if path.endswith(".pvtu"):
        # An MPI run's record: its pieces, one per rank, joined.
        import os
        text = open(path).read()
        joined = None
        for source in re.findall(r'<Piece Source="([^"]+)"', text):
            piece = read_vtu(os.path.join(os.path.dirname(path), source))
            if joined is None:
                joined = piece
                continue
            points, connectivity, offsets, types, fields = joined
            shift, end = len(points), (offsets[-1] if offsets else 0)
            points += piece[0]
            connectivity += [c + shift for c in piece[1]]
            offsets += [o + end for o in piece[2]]
            types += piece[3]
            for name, values in piece[4].items():
                fields[name] = (fields.get(name) or []) + values
        return joined
    text = open(path).read()

    def array(name):
        m = re.search(r'<DataArray([^>]*Name="%s"[^>]*)>(.*?)</DataArray>' % re.escape(name), text, re.S)
        return None if m is None else decode(m.group(1), m.group(2))

    m = re.search(r"<Points>\s*<DataArray([^>]*)>(.*?)</DataArray>", text, re.S)
    if m is None:
        sys.exit(f"plot_rbsn_cells: {path} has no <Points>")
    xyz = decode(m.group(1), m.group(2))
    points = list(zip(xyz[0::3], xyz[1::3]))
    connectivity = [int(v) for v in array("connectivity")]
    offsets = [int(v) for v in array("offsets")]
    types = [int(v) for v in array("types")]
    fields = {}
    for name in re.findall(r'<DataArray[^>]*Name="([^"]+)"', text):
        if name not in ("connectivity", "offsets", "types"):
            fields[name] = array(name)
    return points, connectivity, offsets, types, fields


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("vtu")
    parser.add_argument("png")
    parser.add_argument("--field", default=None, help="cell field to colour by (e.g. H1)")
    parser.add_argument("--magnify", type=float, default=0.0, help="displacement magnification")
    parser.add_argument("--title", default="")
    parser.add_argument("--label", default=None)
    parser.add_argument("--xlim", type=float, nargs=2)
    parser.add_argument("--ylim", type=float, nargs=2)
    parser.add_argument("--width", type=float, default=8.0, help="figure width [in]")
    args = parser.parse_args()

    points, connectivity, offsets, types, fields = read_vtu(args.vtu)
    displacement = fields.get("displacement")
    if args.magnify and displacement is not None:
        points = [(x + args.magnify * displacement[3 * i], y + args.magnify * displacement[3 * i + 1])
                  for i, (x, y) in enumerate(points)]

    polygons, values, cracks = [], [], []
    field = fields.get(args.field) if args.field else None
    if args.field and field is None:
        sys.exit(f"plot_rbsn_cells: {args.vtu} has no cell field '{args.field}' "
                 f"(it has: {', '.join(sorted(fields))})")
    broken = fields.get("broken")
    start = 0
    for c, (end, kind) in enumerate(zip(offsets, types)):
        vertices = [points[k] for k in connectivity[start:end]]
        if kind == 3:
            if broken is None or broken[c] == 1:
                cracks.append(vertices)
        else:
            polygons.append(vertices)
            if field is not None:
                values.append(field[c])
        start = end

    xs = [p[0] for poly in polygons for p in poly]
    ys = [p[1] for poly in polygons for p in poly]
    aspect = (max(ys) - min(ys)) / max(max(xs) - min(xs), 1e-300)
    if args.xlim and args.ylim:
        aspect = (args.ylim[1] - args.ylim[0]) / (args.xlim[1] - args.xlim[0])
    fig, ax = plt.subplots(figsize=(args.width, max(2.0, args.width * aspect + 1.2)))
    cells = PolyCollection(polygons, edgecolors="0.35", linewidths=0.4,
                           facecolors="0.92" if field is None else None, cmap="viridis")
    if field is not None:
        cells.set_array(values)
        cells.set_clim(0, max(1.0, max(values)) if args.field == "H1" else None)
        fig.colorbar(cells, ax=ax, label=args.label or args.field, shrink=0.8)
    ax.add_collection(cells)
    if cracks:
        ax.add_collection(LineCollection(cracks, colors="red", linewidths=1.6,
                                         label=f"broken facets ({len(cracks)})"))
        ax.legend(loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(*(args.xlim or (min(xs), max(xs))))
    ax.set_ylim(*(args.ylim or (min(ys), max(ys))))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    title = args.title + (f" (displacements x{args.magnify:g})" if args.magnify else "")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(args.png, dpi=130)


if __name__ == "__main__":
    main()
