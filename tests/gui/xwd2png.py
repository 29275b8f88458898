#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Convert an XWD image (e.g. Xvfb's -fbdir frame buffer, Xvfb_screen0) to PNG.

    xwd2png.py SCREEN.xwd OUT.png [--crop X,Y,W,H] [--scale N]

Python 3 standard library only: TrueColor ZPixmap images with 24 or 32 bits
per pixel (what Xvfb -screen 0 WxHx24 writes). --scale N keeps every N-th
pixel. Rows are PNG-filtered (Sub/Up, whichever is smaller) to stay small.
"""
import argparse
import struct
import sys
import zlib

FIELDS = ("header_size file_version pixmap_format pixmap_depth pixmap_width pixmap_height xoffset "
          "byte_order bitmap_unit bitmap_bit_order bitmap_pad bits_per_pixel bytes_per_line "
          "visual_class red_mask green_mask blue_mask bits_per_rgb colormap_entries ncolors "
          "window_width window_height window_x window_y window_bdrwidth").split()


def read_xwd(data):
    # The header is written in the writer's byte order: header_size (>= 100) tells which.
    for order in (">", "<"):
        h = dict(zip(FIELDS, struct.unpack(order + "25I", data[:100])))
        if 100 <= h["header_size"] < 4096 and h["file_version"] == 7:
            break
    else:
        raise ValueError("not an XWD file (version 7)")
    if h["pixmap_format"] != 2 or h["bits_per_pixel"] not in (24, 32) or h["visual_class"] not in (4, 5):
        raise ValueError("only TrueColor/DirectColor ZPixmap with 24 or 32 bits per pixel: %r" % h)
    offset = h["header_size"] + 12 * h["ncolors"]
    w, h_, bpl, bpp = h["pixmap_width"], h["pixmap_height"], h["bytes_per_line"], h["bits_per_pixel"] // 8
    pixels = data[offset:offset + bpl * h_]
    if len(pixels) < bpl * h_:
        raise ValueError("truncated XWD data")
    # Where the red, green and blue bytes are within a pixel (masks are byte aligned here).
    little = h["byte_order"] == 0

    def byte_index(mask):
        shift = (mask & -mask).bit_length() - 1
        if shift % 8:
            raise ValueError("colour masks not byte aligned")
        b = shift // 8
        return b if little else bpp - 1 - b
    idx = [byte_index(h[k]) for k in ("red_mask", "green_mask", "blue_mask")]
    return w, h_, bpl, bpp, pixels, idx


def to_rgb_rows(w, h, bpl, bpp, pixels, idx, crop, scale):
    x0, y0, cw, ch = crop or (0, 0, w, h)
    cw, ch = min(cw, w - x0), min(ch, h - y0)
    r, g, b = idx
    rows = []
    for y in range(y0, y0 + ch, scale):
        line = pixels[y * bpl + x0 * bpp:y * bpl + (x0 + cw) * bpp]
        row = bytearray(len(range(0, cw, scale)) * 3)
        step = bpp * scale
        row[0::3] = line[r::step]
        row[1::3] = line[g::step]
        row[2::3] = line[b::step]
        rows.append(bytes(row))
    return rows


def png(rows):
    width = len(rows[0]) // 3
    raw = bytearray()
    prev = bytes(len(rows[0]))
    for row in rows:
        sub = bytes((row[i] - (row[i - 3] if i >= 3 else 0)) & 0xFF for i in range(len(row)))
        up = bytes((a - b) & 0xFF for a, b in zip(row, prev))
        # Fewer distinct/non-zero bytes compress better; a cheap heuristic.
        best = min(((0, row), (1, sub), (2, up)), key=lambda c: sum(1 for v in c[1] if v))
        raw.append(best[0])
        raw += best[1]
        prev = row

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, len(rows), 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 9))
            + chunk(b"IEND", b""))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("xwd")
    ap.add_argument("png")
    ap.add_argument("--crop", help="X,Y,W,H")
    ap.add_argument("--scale", type=int, default=1)
    a = ap.parse_args(argv)
    with open(a.xwd, "rb") as fh:
        data = fh.read()
    try:
        w, h, bpl, bpp, pixels, idx = read_xwd(data)
    except ValueError as e:
        print("xwd2png: %s: %s" % (a.xwd, e), file=sys.stderr)
        return 1
    crop = tuple(int(v) for v in a.crop.split(",")) if a.crop else None
    rows = to_rgb_rows(w, h, bpl, bpp, pixels, idx, crop, max(1, a.scale))
    with open(a.png, "wb") as fh:
        fh.write(png(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
