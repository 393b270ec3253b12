#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_plot3d (tests/fuzz/corpus/plot3d/): small valid Plot3D grids
in every layout the reader accepts. Run from anywhere; rewrites the files in place."""
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "plot3d")


def block(dims, shift):
    """Sheared, right-handed block: coordinate d = shift + 0.5 i_d + 0.125 i_(d+1)."""
    n = 1
    for s in dims:
        n *= s
    dim = len(dims)
    pts = []
    for k in range(n):
        i, r = [], k
        for s in dims:
            i.append(r % s)
            r //= s
        pts.append([shift + 0.5 * i[d] + 0.125 * i[(d + 1) % dim] for d in range(dim)])
    return dims, pts


def grid(dim, nblocks):
    return [block([2 + (b + d) % 3 for d in range(dim)], 4.0 * b) for b in range(nblocks)]


def ascii(g, fmt="{:.17g}", exp=None):
    lines = [str(len(g))] + [" ".join(str(s) for s in dims) for dims, _ in g]
    for dims, pts in g:
        for d in range(len(dims)):
            vals = [fmt.format(p[d]) for p in pts]
            if exp:
                vals = [exp(v) for v in vals]
            lines.append(" ".join(vals))
    return ("\n".join(lines) + "\n").encode()


def binary(g, marker=4, order="<", real="d"):
    out = bytearray()
    mfmt = order + ("i" if marker == 4 else "q")

    def record(body):
        if marker:
            out.extend(struct.pack(mfmt, len(body)))
        out.extend(body)
        if marker:
            out.extend(struct.pack(mfmt, len(body)))

    record(struct.pack(order + "i", len(g)))
    record(b"".join(struct.pack(order + "i", s) for dims, _ in g for s in dims))
    for dims, pts in g:
        record(b"".join(struct.pack(order + real, p[d]) for d in range(len(dims)) for p in pts))
    return bytes(out)


def fortran_d(v):
    return "{:.16E}".format(float(v)).replace("E", "D")


def main():
    os.makedirs(OUT, exist_ok=True)
    files = {
        "ascii_2d_1block.xyz": ascii(grid(2, 1)),
        "ascii_3d_1block.xyz": ascii(grid(3, 1)),
        "ascii_2d_3blocks.xyz": ascii(grid(2, 3)),
        "ascii_3d_2blocks.xyz": ascii(grid(3, 2)),
        "ascii_2d_fortran_d.xyz": ascii(grid(2, 2), exp=fortran_d),
        "ascii_2d_bom.xyz": b"\xef\xbb\xbf" + ascii(grid(2, 1)),
        "bin_fortran4_2d_2blocks.xyz": binary(grid(2, 2)),
        "bin_fortran4_3d_1block.xyz": binary(grid(3, 1)),
        "bin_fortran8_2d_2blocks.xyz": binary(grid(2, 2), marker=8),
        "bin_fortran8_3d_1block.xyz": binary(grid(3, 1), marker=8),
        "bin_cstream_2d_4blocks.xyz": binary(grid(2, 4), marker=0),
        "bin_cstream_3d_1block.xyz": binary(grid(3, 1), marker=0),
        "bin_fortran4_bigendian_2d.xyz": binary(grid(2, 2), order=">"),
        "bin_fortran4_float32_3d.xyz": binary(grid(3, 1), real="f"),
    }
    for name, data in files.items():
        assert len(data) < 2048, name
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
