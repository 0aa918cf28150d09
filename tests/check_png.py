#!/usr/bin/env python3
"""tests/check_png.py - verifies the PNG files written by examples/image.h (python3 stdlib only).

Usage (from the repository root):

    ./build/png_check build && python3 tests/check_png.py build
    python3 tests/check_png.py build/pattern.png build/pattern.rgb [more.png more.rgb ...]

With a single directory argument it checks every NAME.png and NAME.ppm in it that has a NAME.rgb
beside it (the raw RGB bytes, w * h * 3, row-major, top row first, as tests/png_check.c writes
them); otherwise the arguments are (image, rgb) pairs. For each PNG it:

  - checks the signature, the chunk layout and every chunk's CRC (zlib.crc32), that IHDR comes
    first and says 8-bit truecolour RGB, compression 0, filter 0, no interlace; that the IDAT
    chunks are consecutive and that IEND is last with nothing after it;
  - concatenates the IDAT data, checks the zlib header and that the first DEFLATE block is
    compressed (BTYPE 01 or 10, not stored), inflates it with zlib.decompress (which also checks
    the Adler-32 trailer) and checks its length is h * (1 + 3 * w);
  - undoes the per-row filters (all five PNG filter types: None, Sub, Up, Average, Paeth);
  - compares the pixels byte for byte with the .rgb file;
  - for a stream of fixed-Huffman blocks, decodes the DEFLATE symbols itself (independently of
    zlib) to count literals and matches and report the longest length and distance used.

It prints "png ok: <file> <w>x<h> ratio <compressed/raw> ..." per PNG, where compressed is the
zlib stream's size and raw is w * h * 3, and exits non-zero on any mismatch.
"""

import os
import struct
import sys
import zlib

SIGNATURE = b"\x89PNG\r\n\x1a\n"


class CheckError(Exception):
    pass


def read_chunks(data):
    if data[:8] != SIGNATURE:
        raise CheckError("bad PNG signature")
    at, chunks = 8, []
    while at < len(data):
        if at + 12 > len(data):
            raise CheckError("truncated chunk header at byte %d" % at)
        (length,) = struct.unpack(">I", data[at : at + 4])
        kind = data[at + 4 : at + 8]
        body = data[at + 8 : at + 8 + length]
        if len(body) != length or at + 12 + length > len(data):
            raise CheckError("truncated %r chunk" % kind)
        (crc,) = struct.unpack(">I", data[at + 8 + length : at + 12 + length])
        if zlib.crc32(kind + body) & 0xFFFFFFFF != crc:
            raise CheckError("CRC mismatch in %r chunk at byte %d" % (kind, at))
        chunks.append((kind, body))
        at += 12 + length
        if kind == b"IEND":
            break
    if at != len(data):
        raise CheckError("%d bytes after IEND (or no IEND)" % (len(data) - at))
    return chunks


def unfilter(raw, width, height, bpp=3):
    """Undoes the PNG filters of every scanline (PNG spec 9.2, filter method 0)."""
    stride = width * bpp
    out = bytearray()
    prior = bytearray(stride)
    used = [0] * 5
    for y in range(height):
        at = y * (stride + 1)
        kind = raw[at]
        line = bytearray(raw[at + 1 : at + 1 + stride])
        if kind == 0:  # None
            pass
        elif kind == 1:  # Sub: Raw(x) = Sub(x) + Raw(x - bpp)
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 255
        elif kind == 2:  # Up: Raw(x) = Up(x) + Prior(x)
            for i in range(stride):
                line[i] = (line[i] + prior[i]) & 255
        elif kind == 3:  # Average: Raw(x) = Average(x) + floor((Raw(x - bpp) + Prior(x)) / 2)
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prior[i]) >> 1)) & 255
        elif kind == 4:  # Paeth: predictor chosen from left (a), above (b), upper left (c)
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prior[i]
                c = prior[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        else:
            raise CheckError("row %d has unknown filter type %d" % (y, kind))
        used[kind] += 1
        out += line
        prior = line
    return bytes(out), used


class BitReader:
    """RFC 1951 3.1.1: bits are read from each byte starting with the least significant."""

    def __init__(self, data):
        self.data = bytes(data) + b"\0\0\0\0"
        self.pos = 0
        self.end = 8 * len(data)

    def bits(self, n):  # n <= 24
        if self.pos + n > self.end:
            raise CheckError("DEFLATE stream ends inside a symbol")
        at = self.pos >> 3
        v = int.from_bytes(self.data[at : at + 4], "little") >> (self.pos & 7)
        self.pos += n
        return v & ((1 << n) - 1)

    def code(self, n):  # a Huffman code of n bits: its first bit is its most significant
        v, r = self.bits(n), 0
        for _ in range(n):
            r, v = (r << 1) | (v & 1), v >> 1
        return r


LEN_BASE = [3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99,
            115, 131, 163, 195, 227, 258]
LEN_EXTRA = [0] * 8 + [1] * 4 + [2] * 4 + [3] * 4 + [4] * 4 + [5] * 4 + [0]
DIST_BASE = [1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025,
             1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577]
DIST_EXTRA = [0, 0, 0, 0] + [i // 2 - 1 for i in range(4, 30)]


def fixed_symbol(br):
    """One literal/length symbol in the fixed Huffman code of RFC 1951 3.2.6."""
    v = br.code(7)
    if v <= 0x17:
        return 256 + v  # 7 bits: 256-279
    v = (v << 1) | br.bits(1)
    if 0x30 <= v <= 0xBF:
        return v - 0x30  # 8 bits: 0-143
    if 0xC0 <= v <= 0xC7:
        return 280 + v - 0xC0  # 8 bits: 280-287
    v = (v << 1) | br.bits(1)
    return 144 + v - 0x190  # 9 bits: 144-255


def deflate_stats(stream):
    """Counts the symbols of a zlib stream made of fixed-Huffman blocks and re-inflates it;
    returns None if it holds another kind of block."""
    br = BitReader(stream[2:-4])
    out = bytearray()
    literals = matches = longest = farthest = 0
    final = 0
    while not final:
        final, btype = br.bits(1), br.bits(2)
        if btype != 1:
            return None
        while True:
            sym = fixed_symbol(br)
            if sym < 256:
                out.append(sym)
                literals += 1
                continue
            if sym == 256:
                break
            if sym > 285:
                raise CheckError("invalid length symbol %d" % sym)
            i = sym - 257
            length = LEN_BASE[i] + br.bits(LEN_EXTRA[i])
            d = br.code(5)
            if d > 29:
                raise CheckError("invalid distance code %d" % d)
            dist = DIST_BASE[d] + br.bits(DIST_EXTRA[d])
            if dist > len(out) or dist > 32768:
                raise CheckError("distance %d reaches before the data or the window" % dist)
            if length > 258:
                raise CheckError("length %d" % length)
            for _ in range(length):
                out.append(out[-dist])
            matches += 1
            longest = max(longest, length)
            farthest = max(farthest, dist)
    return bytes(out), literals, matches, longest, farthest


def check_png(png_path, rgb_path):
    with open(png_path, "rb") as f:
        data = f.read()
    with open(rgb_path, "rb") as f:
        expected = f.read()
    print(check_png_data(png_path, data, expected))


def check_png_data(png_path, data, expected):
    """Checks one PNG file's bytes against the expected RGB bytes; returns the report line."""
    chunks = read_chunks(data)
    kinds = [k for k, _ in chunks]
    if kinds[0] != b"IHDR" or len(chunks[0][1]) != 13:
        raise CheckError("the first chunk is not a 13-byte IHDR")
    if kinds[-1] != b"IEND" or chunks[-1][1]:
        raise CheckError("the last chunk is not an empty IEND")
    w, h, depth, colour, comp, filt, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    if w == 0 or h == 0 or w > 2**31 - 1 or h > 2**31 - 1:
        raise CheckError("bad size %dx%d" % (w, h))
    if (depth, colour, comp, filt, interlace) != (8, 2, 0, 0, 0):
        raise CheckError("IHDR is not 8-bit RGB, deflate, filter 0, no interlace: %r"
                         % ((depth, colour, comp, filt, interlace),))
    idat_at = [i for i, k in enumerate(kinds) if k == b"IDAT"]
    if not idat_at or idat_at != list(range(idat_at[0], idat_at[-1] + 1)):
        raise CheckError("IDAT chunks missing or not consecutive")
    for k in kinds:
        if k[0] & 0x20 == 0 and k not in (b"IHDR", b"IDAT", b"IEND", b"PLTE"):
            raise CheckError("unknown critical chunk %r" % k)
    stream = b"".join(body for k, body in chunks if k == b"IDAT")
    if len(stream) < 6:
        raise CheckError("zlib stream too short")
    cmf, flg = stream[0], stream[1]
    if cmf & 15 != 8 or cmf >> 4 > 7 or (cmf * 256 + flg) % 31 or flg & 0x20:
        raise CheckError("bad zlib header %02x %02x" % (cmf, flg))
    btype = (stream[2] >> 1) & 3
    if btype not in (1, 2):
        raise CheckError("first DEFLATE block has BTYPE %d, not a compressed block" % btype)
    raw = zlib.decompress(stream)  # checks the DEFLATE data and the Adler-32 trailer
    if len(raw) != h * (1 + 3 * w):
        raise CheckError("inflated %d bytes, expected %d" % (len(raw), h * (1 + 3 * w)))
    pixels, used = unfilter(raw, w, h)
    if len(expected) != w * h * 3:
        raise CheckError("the .rgb file has %d bytes, expected %d" % (len(expected), w * h * 3))
    if pixels != expected:
        first = next(i for i in range(len(pixels)) if pixels[i] != expected[i])
        raise CheckError("pixel mismatch at byte %d (x %d, y %d)"
                         % (first, first // 3 % w, first // 3 // w))
    line = "png ok: %s %dx%d ratio %.4f (zlib %d / raw %d bytes, file %d, %d IDAT, filters %s)" % (
        png_path, w, h, len(stream) / (w * h * 3), len(stream), w * h * 3, len(data),
        len(idat_at), "/".join(str(n) for n in used))
    stats = deflate_stats(stream)
    if stats is not None:
        inflated, literals, matches, longest, farthest = stats
        if inflated != raw:
            raise CheckError("own fixed-Huffman decoder disagrees with zlib")
        line += "\n        fixed-Huffman: %d literals, %d matches, longest %d, farthest %d" % (
            literals, matches, longest, farthest)
    return line


def encode_png(w, h, rgb, filters):
    """A reference encoder for the self-test: applies the given filter type to each row (the
    forward filters of PNG spec 9.2) and compresses with zlib."""
    stride, prior, raw = 3 * w, bytearray(3 * w), bytearray()
    for y in range(h):
        line = rgb[y * stride : (y + 1) * stride]
        kind = filters[y % len(filters)]
        out = bytearray()
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prior[i]
            c = prior[i - 3] if i >= 3 else 0
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            paeth = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            pred = (0, a, b, (a + b) >> 1, paeth)[kind]
            out.append((line[i] - pred) & 255)
        raw += bytes([kind]) + out
        prior = line

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return (SIGNATURE + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 9))
            + chunk(b"IEND", b""))


def self_test():
    """Checks the checker: all five filters decode, and corruption is caught."""
    w, h, state, rgb = 16, 40, 0x2545F491, bytearray()
    for i in range(w * h * 3):  # xorshift32 bytes: full-range rows, then few-valued rows (ties)
        state ^= (state << 13) & 0xFFFFFFFF
        state ^= state >> 17
        state ^= (state << 5) & 0xFFFFFFFF
        rgb.append(state & 255 if i < w * h * 3 // 2 else (state & 3) * 60)
    rgb = bytes(rgb)
    png = encode_png(w, h, rgb, [0, 1, 2, 3, 4, 4, 3, 2, 1, 0])
    check_png_data("self-test", png, rgb)
    for what, bad_png, bad_rgb in (
        ("a flipped IDAT byte", png[:45] + bytes([png[45] ^ 1]) + png[46:], rgb),
        ("a wrong pixel", png, rgb[:50] + bytes([rgb[50] ^ 1]) + rgb[51:]),
        ("a short .rgb file", png, rgb[:-1]),
        ("bytes after IEND", png + b"\0", rgb),
    ):
        try:
            check_png_data("self-test", bad_png, bad_rgb)
        except (CheckError, zlib.error):
            continue
        raise CheckError("self-test: %s was not detected" % what)


def check_ppm(ppm_path, rgb_path):
    with open(ppm_path, "rb") as f:
        data = f.read()
    with open(rgb_path, "rb") as f:
        expected = f.read()
    fields, at = [], 0
    while len(fields) < 4:  # magic, width, height, maxval, separated by single whitespace here
        end = at
        while data[end : end + 1] not in (b" ", b"\n", b"\t", b"\r"):
            end += 1
        fields.append(data[at:end])
        at = end + 1
    if fields[0] != b"P6" or fields[3] != b"255":
        raise CheckError("not an 8-bit P6 PPM")
    w, h = int(fields[1]), int(fields[2])
    if data[at:] != expected or len(expected) != w * h * 3:
        raise CheckError("PPM pixels differ from %s" % rgb_path)
    print("ppm ok: %s %dx%d" % (ppm_path, w, h))


def main(argv):
    if len(argv) == 1 and os.path.isdir(argv[0]):
        pairs = []
        for name in sorted(os.listdir(argv[0])):
            stem, ext = os.path.splitext(name)
            rgb = os.path.join(argv[0], stem + ".rgb")
            if ext in (".png", ".ppm") and os.path.exists(rgb):
                pairs.append((os.path.join(argv[0], name), rgb))
        if not pairs:
            print("check_png: no NAME.png with a NAME.rgb in %s" % argv[0])
            return 1
    elif argv and len(argv) % 2 == 0:
        pairs = list(zip(argv[0::2], argv[1::2]))
    else:
        print("\n\n".join(__doc__.split("\n\n")[1:3]))
        return 2
    try:
        self_test()
        print("check_png: self-test ok (filters 0-4 decode, corruption detected)")
    except (CheckError, zlib.error) as e:
        print("check_png: self-test FAILED: %s" % e)
        return 1
    failed = 0
    for image, rgb in pairs:
        try:
            (check_ppm if image.endswith(".ppm") else check_png)(image, rgb)
        except (CheckError, OSError, zlib.error, ValueError) as e:
            print("png FAILED: %s: %s" % (image, e))
            failed += 1
    print("check_png: %d passed, %d failed" % (len(pairs) - failed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
