/* examples/image.h - a small dependency-free image module for the sph.h examples.

   Header-only C99 (also compiles as C++11), libc + libm only. Every function is static, so each
   file that includes it gets its own private copy; there is nothing to link.

   Images are 8-bit RGB, row-major, top row first: pixel (x, y) is rgb[3 * (y * w + x) + 0..2].
   Drawing uses continuous pixel coordinates: pixel (x, y) covers [x, x+1) x [y, y+1), so its centre
   is (x + 0.5, y + 0.5). Everything drawn is clipped to the image.

     typedef struct img { int w, h; unsigned char* rgb; } img;

     int  img_init(img* im, int w, int h);       black w x h image; 1 on success, 0 on bad size or
                                                 allocation failure (im is then empty)
     void img_free(img* im);                     frees and empties; safe on an empty image
     void img_fill(img* im, r, g, b);
     void img_put(img* im, int x, int y, r, g, b);                 one pixel (clipped)
     void img_blend(img* im, int x, int y, double a, r, g, b);     pixel += a * (colour - pixel)
     void img_rect(img* im, int x0, int y0, int x1, int y1, r, g, b);
                                                 pixels min(x0,x1) <= x < max(x0,x1), same for y
     void img_disc(img* im, double cx, double cy, double radius, r, g, b);
                                                 filled disc, edge anti-aliased by coverage blending
     void img_colormap(double t, unsigned char* rgb);
                                                 viridis-like map of t in [0,1] (clamped) to rgb[3]
     int  img_text(img* im, int x, int y, int scale, const char* s, r, g, b);
                                                 5x7 font (descenders below) in 6x11 cells scaled by
                                                 scale; (x, y) is the top-left corner; '\n' starts a
                                                 new line; returns the x after the last character
     int  img_text_width(int scale, const char* s);   width of the longest line in pixels
     int  img_write_png(const img* im, const char* path);   0 on success, -1 on failure
     int  img_write_ppm(const img* im, const char* path);   0 on success, -1 on failure

   Colours r, g, b are unsigned char. The PNG writer is self-contained: PNG filters None/Sub chosen
   per row, a zlib stream with LZ77 (hash chains over a 32 KiB window) and fixed-Huffman DEFLATE,
   CRC-32 and Adler-32. tests/png_check.c and tests/check_png.py verify it against Python's zlib. */
#ifndef SPH_EXAMPLES_IMAGE_H
#define SPH_EXAMPLES_IMAGE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define IMGDEF static __attribute__((unused))
#else
#define IMGDEF static
#endif

typedef struct img {
    int w, h;
    unsigned char* rgb;
} img;

/* ---- allocation and pixels ------------------------------------------------------------------ */

IMGDEF int img_init(img* im, int w, int h) {
    im->w = im->h = 0;
    im->rgb = NULL;
    if (w <= 0 || h <= 0 || (size_t)w > (size_t)-1 / 3 / (size_t)h) return 0;
    im->rgb = (unsigned char*)calloc((size_t)w * (size_t)h, 3);
    if (!im->rgb) return 0;
    im->w = w;
    im->h = h;
    return 1;
}

IMGDEF void img_free(img* im) {
    free(im->rgb);
    im->rgb = NULL;
    im->w = im->h = 0;
}

IMGDEF void img_fill(img* im, unsigned char r, unsigned char g, unsigned char b) {
    size_t i, n = (size_t)im->w * (size_t)im->h;
    for (i = 0; i < n; i++) {
        im->rgb[3 * i + 0] = r;
        im->rgb[3 * i + 1] = g;
        im->rgb[3 * i + 2] = b;
    }
}

IMGDEF void img_put(img* im, int x, int y, unsigned char r, unsigned char g, unsigned char b) {
    unsigned char* p;
    if (x < 0 || y < 0 || x >= im->w || y >= im->h) return;
    p = im->rgb + 3 * ((size_t)y * (size_t)im->w + (size_t)x);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

static unsigned char img__mix(unsigned char from, unsigned char to, double a) {
    return (unsigned char)(from + (to - from) * a + 0.5); /* stays within [from, to] */
}

IMGDEF void img_blend(img* im, int x, int y, double a, unsigned char r, unsigned char g,
                      unsigned char b) {
    unsigned char* p;
    if (x < 0 || y < 0 || x >= im->w || y >= im->h || !(a > 0.0)) return; /* also rejects NaN */
    if (a > 1.0) a = 1.0;
    p = im->rgb + 3 * ((size_t)y * (size_t)im->w + (size_t)x);
    p[0] = img__mix(p[0], r, a);
    p[1] = img__mix(p[1], g, a);
    p[2] = img__mix(p[2], b, a);
}

/* Clamps v to [0, hi] before converting, so huge or NaN coordinates cannot overflow an int. */
static int img__clampi(double v, int hi) {
    if (!(v > 0.0)) return 0;
    if (v > (double)hi) return hi;
    return (int)v;
}

IMGDEF void img_rect(img* im, int x0, int y0, int x1, int y1, unsigned char r, unsigned char g,
                     unsigned char b) {
    int x, y, t;
    if (x0 > x1) { t = x0; x0 = x1; x1 = t; }
    if (y0 > y1) { t = y0; y0 = y1; y1 = t; }
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > im->w) x1 = im->w;
    if (y1 > im->h) y1 = im->h;
    for (y = y0; y < y1; y++)
        for (x = x0; x < x1; x++) img_put(im, x, y, r, g, b);
}

/* Coverage of a pixel is approximated by a one-pixel-wide linear ramp across the edge:
   clamp(radius + 0.5 - distance from the pixel centre, 0, 1). Discs thinner than a pixel are
   faded by their diameter so that they vanish smoothly instead of staying one full pixel. */
IMGDEF void img_disc(img* im, double cx, double cy, double radius, unsigned char r,
                     unsigned char g, unsigned char b) {
    int x, y, x0, x1, y0, y1;
    double fade;
    if (!im->rgb || !(radius > 0.0)) return;
    fade = radius < 0.5 ? 2.0 * radius : 1.0;
    x0 = img__clampi(floor(cx - radius - 0.5), im->w);
    x1 = img__clampi(ceil(cx + radius + 0.5), im->w);
    y0 = img__clampi(floor(cy - radius - 0.5), im->h);
    y1 = img__clampi(ceil(cy + radius + 0.5), im->h);
    for (y = y0; y < y1; y++) {
        double dy = y + 0.5 - cy;
        for (x = x0; x < x1; x++) {
            double dx = x + 0.5 - cx;
            double cover = radius + 0.5 - sqrt(dx * dx + dy * dy);
            if (cover >= 1.0 && fade >= 1.0)
                img_put(im, x, y, r, g, b);
            else if (cover > 0.0)
                img_blend(im, x, y, (cover < 1.0 ? cover : 1.0) * fade, r, g, b);
        }
    }
}

/* ---- colour map ----------------------------------------------------------------------------- */

/* Piecewise-linear map through 9 control points at t = 0, 1/8, ..., 1 sampled from the viridis
   colour map (dark violet - blue - teal - green - yellow): lightness rises monotonically, so the
   order of values reads correctly in colour and in grey. */
IMGDEF void img_colormap(double t, unsigned char* rgb) {
    static const unsigned char stops[9][3] = {
        {68, 1, 84},   {71, 44, 122},  {59, 82, 139},  {44, 114, 142}, {33, 145, 140},
        {40, 174, 128}, {94, 201, 98}, {173, 220, 48}, {253, 231, 37}};
    double u;
    int i, k;
    if (!(t > 0.0)) t = 0.0; /* also maps NaN to 0 */
    if (t > 1.0) t = 1.0;
    u = t * 8.0;
    i = (int)u;
    if (i > 7) i = 7;
    u -= i;
    for (k = 0; k < 3; k++) rgb[k] = img__mix(stops[i][k], stops[i + 1][k], u);
}

/* ---- text ----------------------------------------------------------------------------------- */

#define IMG_FONT_ADVANCE 6 /* cell width: 5 columns of glyph + 1 of spacing */
#define IMG_FONT_LINE 11   /* cell height: 7 rows above the baseline, 2 below, 2 of spacing */

/* Glyphs for ASCII 32..126, 9 rows each (rows 0-6 stand on the baseline, rows 7-8 hold
   descenders); bit 4 of a row is the leftmost of its 5 columns. */
static const unsigned char* img__glyph(unsigned char c) {
    static const unsigned char font[95][9] = {
        {0x00,0x00,0x00,0x00,0x00,0x00,0x00,0x00,0x00}, /* space */
        {0x04,0x04,0x04,0x04,0x04,0x00,0x04,0x00,0x00}, /* ! */
        {0x0A,0x0A,0x0A,0x00,0x00,0x00,0x00,0x00,0x00}, /* " */
        {0x0A,0x0A,0x1F,0x0A,0x1F,0x0A,0x0A,0x00,0x00}, /* # */
        {0x04,0x0F,0x14,0x0E,0x05,0x1E,0x04,0x00,0x00}, /* $ */
        {0x18,0x19,0x02,0x04,0x08,0x13,0x03,0x00,0x00}, /* % */
        {0x0C,0x12,0x14,0x08,0x15,0x12,0x0D,0x00,0x00}, /* & */
        {0x04,0x04,0x08,0x00,0x00,0x00,0x00,0x00,0x00}, /* quote */
        {0x02,0x04,0x08,0x08,0x08,0x04,0x02,0x00,0x00}, /* ( */
        {0x08,0x04,0x02,0x02,0x02,0x04,0x08,0x00,0x00}, /* ) */
        {0x00,0x04,0x15,0x0E,0x15,0x04,0x00,0x00,0x00}, /* * */
        {0x00,0x04,0x04,0x1F,0x04,0x04,0x00,0x00,0x00}, /* + */
        {0x00,0x00,0x00,0x00,0x00,0x0C,0x04,0x08,0x00}, /* , */
        {0x00,0x00,0x00,0x1F,0x00,0x00,0x00,0x00,0x00}, /* - */
        {0x00,0x00,0x00,0x00,0x00,0x0C,0x0C,0x00,0x00}, /* . */
        {0x01,0x01,0x02,0x04,0x08,0x10,0x10,0x00,0x00}, /* / */
        {0x0E,0x11,0x13,0x15,0x19,0x11,0x0E,0x00,0x00}, /* 0 */
        {0x04,0x0C,0x04,0x04,0x04,0x04,0x0E,0x00,0x00}, /* 1 */
        {0x0E,0x11,0x01,0x02,0x04,0x08,0x1F,0x00,0x00}, /* 2 */
        {0x1F,0x02,0x04,0x02,0x01,0x11,0x0E,0x00,0x00}, /* 3 */
        {0x02,0x06,0x0A,0x12,0x1F,0x02,0x02,0x00,0x00}, /* 4 */
        {0x1F,0x10,0x1E,0x01,0x01,0x11,0x0E,0x00,0x00}, /* 5 */
        {0x06,0x08,0x10,0x1E,0x11,0x11,0x0E,0x00,0x00}, /* 6 */
        {0x1F,0x01,0x02,0x04,0x08,0x08,0x08,0x00,0x00}, /* 7 */
        {0x0E,0x11,0x11,0x0E,0x11,0x11,0x0E,0x00,0x00}, /* 8 */
        {0x0E,0x11,0x11,0x0F,0x01,0x02,0x0C,0x00,0x00}, /* 9 */
        {0x00,0x0C,0x0C,0x00,0x0C,0x0C,0x00,0x00,0x00}, /* : */
        {0x00,0x0C,0x0C,0x00,0x0C,0x04,0x08,0x00,0x00}, /* ; */
        {0x02,0x04,0x08,0x10,0x08,0x04,0x02,0x00,0x00}, /* < */
        {0x00,0x00,0x1F,0x00,0x1F,0x00,0x00,0x00,0x00}, /* = */
        {0x08,0x04,0x02,0x01,0x02,0x04,0x08,0x00,0x00}, /* > */
        {0x0E,0x11,0x01,0x02,0x04,0x00,0x04,0x00,0x00}, /* ? */
        {0x0E,0x11,0x17,0x15,0x17,0x10,0x0E,0x00,0x00}, /* @ */
        {0x0E,0x11,0x11,0x1F,0x11,0x11,0x11,0x00,0x00}, /* A */
        {0x1E,0x11,0x11,0x1E,0x11,0x11,0x1E,0x00,0x00}, /* B */
        {0x0E,0x11,0x10,0x10,0x10,0x11,0x0E,0x00,0x00}, /* C */
        {0x1E,0x11,0x11,0x11,0x11,0x11,0x1E,0x00,0x00}, /* D */
        {0x1F,0x10,0x10,0x1E,0x10,0x10,0x1F,0x00,0x00}, /* E */
        {0x1F,0x10,0x10,0x1E,0x10,0x10,0x10,0x00,0x00}, /* F */
        {0x0E,0x11,0x10,0x17,0x11,0x11,0x0F,0x00,0x00}, /* G */
        {0x11,0x11,0x11,0x1F,0x11,0x11,0x11,0x00,0x00}, /* H */
        {0x0E,0x04,0x04,0x04,0x04,0x04,0x0E,0x00,0x00}, /* I */
        {0x07,0x02,0x02,0x02,0x02,0x12,0x0C,0x00,0x00}, /* J */
        {0x11,0x12,0x14,0x18,0x14,0x12,0x11,0x00,0x00}, /* K */
        {0x10,0x10,0x10,0x10,0x10,0x10,0x1F,0x00,0x00}, /* L */
        {0x11,0x1B,0x15,0x15,0x11,0x11,0x11,0x00,0x00}, /* M */
        {0x11,0x11,0x19,0x15,0x13,0x11,0x11,0x00,0x00}, /* N */
        {0x0E,0x11,0x11,0x11,0x11,0x11,0x0E,0x00,0x00}, /* O */
        {0x1E,0x11,0x11,0x1E,0x10,0x10,0x10,0x00,0x00}, /* P */
        {0x0E,0x11,0x11,0x11,0x15,0x12,0x0D,0x00,0x00}, /* Q */
        {0x1E,0x11,0x11,0x1E,0x14,0x12,0x11,0x00,0x00}, /* R */
        {0x0F,0x10,0x10,0x0E,0x01,0x01,0x1E,0x00,0x00}, /* S */
        {0x1F,0x04,0x04,0x04,0x04,0x04,0x04,0x00,0x00}, /* T */
        {0x11,0x11,0x11,0x11,0x11,0x11,0x0E,0x00,0x00}, /* U */
        {0x11,0x11,0x11,0x11,0x11,0x0A,0x04,0x00,0x00}, /* V */
        {0x11,0x11,0x11,0x15,0x15,0x15,0x0A,0x00,0x00}, /* W */
        {0x11,0x11,0x0A,0x04,0x0A,0x11,0x11,0x00,0x00}, /* X */
        {0x11,0x11,0x0A,0x04,0x04,0x04,0x04,0x00,0x00}, /* Y */
        {0x1F,0x01,0x02,0x04,0x08,0x10,0x1F,0x00,0x00}, /* Z */
        {0x0E,0x08,0x08,0x08,0x08,0x08,0x0E,0x00,0x00}, /* [ */
        {0x10,0x10,0x08,0x04,0x02,0x01,0x01,0x00,0x00}, /* backslash */
        {0x0E,0x02,0x02,0x02,0x02,0x02,0x0E,0x00,0x00}, /* ] */
        {0x04,0x0A,0x11,0x00,0x00,0x00,0x00,0x00,0x00}, /* ^ */
        {0x00,0x00,0x00,0x00,0x00,0x00,0x00,0x1F,0x00}, /* _ */
        {0x08,0x04,0x00,0x00,0x00,0x00,0x00,0x00,0x00}, /* ` */
        {0x00,0x00,0x0E,0x01,0x0F,0x11,0x0F,0x00,0x00}, /* a */
        {0x10,0x10,0x1E,0x11,0x11,0x11,0x1E,0x00,0x00}, /* b */
        {0x00,0x00,0x0E,0x10,0x10,0x11,0x0E,0x00,0x00}, /* c */
        {0x01,0x01,0x0F,0x11,0x11,0x11,0x0F,0x00,0x00}, /* d */
        {0x00,0x00,0x0E,0x11,0x1F,0x10,0x0E,0x00,0x00}, /* e */
        {0x06,0x09,0x08,0x1C,0x08,0x08,0x08,0x00,0x00}, /* f */
        {0x00,0x00,0x0F,0x11,0x11,0x11,0x0F,0x01,0x0E}, /* g */
        {0x10,0x10,0x16,0x19,0x11,0x11,0x11,0x00,0x00}, /* h */
        {0x04,0x00,0x0C,0x04,0x04,0x04,0x0E,0x00,0x00}, /* i */
        {0x02,0x00,0x06,0x02,0x02,0x02,0x02,0x12,0x0C}, /* j */
        {0x10,0x10,0x12,0x14,0x18,0x14,0x12,0x00,0x00}, /* k */
        {0x0C,0x04,0x04,0x04,0x04,0x04,0x0E,0x00,0x00}, /* l */
        {0x00,0x00,0x1A,0x15,0x15,0x15,0x15,0x00,0x00}, /* m */
        {0x00,0x00,0x16,0x19,0x11,0x11,0x11,0x00,0x00}, /* n */
        {0x00,0x00,0x0E,0x11,0x11,0x11,0x0E,0x00,0x00}, /* o */
        {0x00,0x00,0x1E,0x11,0x11,0x11,0x1E,0x10,0x10}, /* p */
        {0x00,0x00,0x0F,0x11,0x11,0x11,0x0F,0x01,0x01}, /* q */
        {0x00,0x00,0x16,0x19,0x10,0x10,0x10,0x00,0x00}, /* r */
        {0x00,0x00,0x0F,0x10,0x0E,0x01,0x1E,0x00,0x00}, /* s */
        {0x08,0x08,0x1C,0x08,0x08,0x09,0x06,0x00,0x00}, /* t */
        {0x00,0x00,0x11,0x11,0x11,0x13,0x0D,0x00,0x00}, /* u */
        {0x00,0x00,0x11,0x11,0x11,0x0A,0x04,0x00,0x00}, /* v */
        {0x00,0x00,0x11,0x11,0x15,0x15,0x0A,0x00,0x00}, /* w */
        {0x00,0x00,0x11,0x0A,0x04,0x0A,0x11,0x00,0x00}, /* x */
        {0x00,0x00,0x11,0x11,0x11,0x11,0x0F,0x01,0x0E}, /* y */
        {0x00,0x00,0x1F,0x02,0x04,0x08,0x1F,0x00,0x00}, /* z */
        {0x03,0x04,0x04,0x08,0x04,0x04,0x03,0x00,0x00}, /* { */
        {0x04,0x04,0x04,0x04,0x04,0x04,0x04,0x00,0x00}, /* | */
        {0x18,0x04,0x04,0x02,0x04,0x04,0x18,0x00,0x00}, /* } */
        {0x00,0x00,0x00,0x0D,0x16,0x00,0x00,0x00,0x00}, /* ~ */
    };
    if (c < 32 || c > 126) c = '?'; /* control characters and non-ASCII bytes */
    return font[c - 32];
}

IMGDEF int img_text(img* im, int x, int y, int scale, const char* s, unsigned char r,
                    unsigned char g, unsigned char b) {
    int cx = x, row, col;
    if (scale < 1) scale = 1;
    for (; *s; s++) {
        const unsigned char* glyph;
        if (*s == '\n') {
            cx = x;
            y += IMG_FONT_LINE * scale;
            continue;
        }
        glyph = img__glyph((unsigned char)(*s == '\t' ? ' ' : *s));
        for (row = 0; row < 9; row++)
            for (col = 0; col < 5; col++)
                if (glyph[row] & (0x10 >> col))
                    img_rect(im, cx + col * scale, y + row * scale, cx + (col + 1) * scale,
                             y + (row + 1) * scale, r, g, b);
        cx += IMG_FONT_ADVANCE * scale;
    }
    return cx;
}

IMGDEF int img_text_width(int scale, const char* s) {
    int n = 0, widest = 0;
    if (scale < 1) scale = 1;
    for (; *s; s++) {
        n = *s == '\n' ? 0 : n + 1;
        if (n > widest) widest = n;
    }
    return widest * IMG_FONT_ADVANCE * scale;
}

/* ---- PNG writer ----------------------------------------------------------------------------- */
/* References: PNG = Portable Network Graphics Specification, 2nd edition (W3C / ISO 15948);
   RFC 1950 = ZLIB data format 3.3; RFC 1951 = DEFLATE data format 1.3. */

/* LSB-first bit writer over a buffer sized in advance (RFC 1951 3.1.1: data elements are packed
   into bytes starting with the least-significant bit). */
typedef struct img__bits {
    unsigned char* buf;
    size_t len, cap;
    uint32_t acc; /* pending bits, the oldest in bit 0 */
    int nacc;     /* number of pending bits, < 8 between calls */
    int full;     /* set if cap was too small (never expected: see img__zlib) */
} img__bits;

static void img__put_bits(img__bits* bw, uint32_t value, int count) {
    bw->acc |= value << bw->nacc;
    bw->nacc += count;
    while (bw->nacc >= 8) {
        if (bw->len < bw->cap) bw->buf[bw->len++] = (unsigned char)bw->acc;
        else bw->full = 1;
        bw->acc >>= 8;
        bw->nacc -= 8;
    }
}

/* Huffman codes are the exception to LSB-first: they are packed starting with their most
   significant bit (RFC 1951 3.1.1), so the code is reversed before it is written. */
static void img__put_code(img__bits* bw, uint32_t code, int length) {
    uint32_t reversed = 0;
    int i;
    for (i = 0; i < length; i++) reversed |= ((code >> i) & 1u) << (length - 1 - i);
    img__put_bits(bw, reversed, length);
}

/* A literal/length symbol 0..287 in the fixed Huffman code of RFC 1951 3.2.6:
   0-143 -> 8 bits from 00110000, 144-255 -> 9 bits from 110010000,
   256-279 -> 7 bits from 0000000, 280-287 -> 8 bits from 11000000. */
static void img__put_symbol(img__bits* bw, int sym) {
    if (sym < 144) img__put_code(bw, 0x30u + (uint32_t)sym, 8);
    else if (sym < 256) img__put_code(bw, 0x190u + (uint32_t)(sym - 144), 9);
    else if (sym < 280) img__put_code(bw, (uint32_t)(sym - 256), 7);
    else img__put_code(bw, 0xC0u + (uint32_t)(sym - 280), 8);
}

/* A <length, backward distance> pair: length symbol 257..285 plus extra bits, then distance code
   0..29 (fixed code: the 5-bit code number) plus extra bits. Tables: RFC 1951 3.2.5. */
static void img__put_match(img__bits* bw, int length, int dist) {
    static const unsigned short len_base[29] = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                                15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                                67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const unsigned char len_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    static const unsigned short dist_base[30] = {
        1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
        193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
    static const unsigned char dist_extra[30] = {0, 0, 0,  0,  1,  1,  2,  2,  3,  3,
                                                 4, 4, 5,  5,  6,  6,  7,  7,  8,  8,
                                                 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
    int l = 28, d = 29;
    while (len_base[l] > length) l--;
    while (dist_base[d] > dist) d--;
    img__put_symbol(bw, 257 + l);
    img__put_bits(bw, (uint32_t)(length - len_base[l]), len_extra[l]);
    img__put_code(bw, (uint32_t)d, 5);
    img__put_bits(bw, (uint32_t)(dist - dist_base[d]), dist_extra[d]);
}

/* Adler-32 of RFC 1950 8.2: s1 = 1 + sum of bytes, s2 = sum of the successive s1, both modulo
   65521. 5552 bytes is the longest run after which s2 cannot yet overflow 32 bits. */
static uint32_t img__adler32(const unsigned char* p, size_t n) {
    uint32_t s1 = 1, s2 = 0;
    while (n > 0) {
        size_t k = n < 5552 ? n : 5552;
        n -= k;
        while (k--) {
            s1 += *p++;
            s2 += s1;
        }
        s1 %= 65521;
        s2 %= 65521;
    }
    return s2 << 16 | s1;
}

#define IMG__WINDOW 32768 /* RFC 1951 3.2: distances reach back at most 32768 bytes */
#define IMG__HASH_BITS 15
#define IMG__CHAIN 32 /* candidates tried per position: enough for flat images, still fast */

static uint32_t img__hash3(const unsigned char* p) { /* multiplicative hash of a 3-byte prefix */
    uint32_t v = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16;
    return (uint32_t)(v * 2654435761u) >> (32 - IMG__HASH_BITS);
}

/* Compresses src[0..n) into a zlib stream (RFC 1950) holding one final DEFLATE block with fixed
   Huffman codes (RFC 1951 3.2.3 BTYPE = 01). Matches are found greedily with hash chains
   (RFC 1951 section 4): head[h] is the newest position whose next 3 bytes hash to h, prev[pos %
   32768] the position before it with the same hash; positions are stored + 1 so 0 means none.
   Returns a malloc'd buffer (length in *out_len) or NULL when out of memory. */
static unsigned char* img__zlib(const unsigned char* src, size_t n, size_t* out_len) {
    img__bits bw;
    size_t* head = (size_t*)calloc((size_t)1 << IMG__HASH_BITS, sizeof(size_t));
    size_t* prev = (size_t*)calloc(IMG__WINDOW, sizeof(size_t));
    size_t pos = 0, i;
    uint32_t adler;
    memset(&bw, 0, sizeof bw);
    /* Output bound: at most 9 bits per input byte (literals 144-255 take 9; a match of k bytes
       takes at most 9k: 22 bits for k = 3 as those stay within 4096, 25 bits for k < 11, 31 bits
       at most), plus zlib header, block header, end-of-block code, padding and trailer. */
    bw.cap = n + n / 8 + 16;
    bw.buf = (unsigned char*)malloc(bw.cap);
    if (!head || !prev || !bw.buf) {
        free(head);
        free(prev);
        free(bw.buf);
        return NULL;
    }
    /* RFC 1950 2.2: CMF = 0x78 (CM 8 = deflate, CINFO 7 = 32 KiB window); FLG has FLEVEL 1
       ("fast") and FCHECK chosen so that CMF * 256 + FLG is a multiple of 31. */
    bw.buf[0] = 0x78;
    bw.buf[1] = (unsigned char)(0x40 + (31 - (0x78 * 256 + 0x40) % 31) % 31);
    bw.len = 2;
    img__put_bits(&bw, 1, 1); /* BFINAL = 1: this is the last (only) block */
    img__put_bits(&bw, 1, 2); /* BTYPE = 01: compressed with fixed Huffman codes */
    while (pos < n) {
        size_t best_len = 0, best_dist = 0, step;
        if (n - pos >= 3) {
            size_t max_len = n - pos < 258 ? n - pos : 258, cand = head[img__hash3(src + pos)];
            int chain = IMG__CHAIN;
            /* Newest first; stop at the window edge. Once the distance is within the window, the
               prev slot of cand cannot have been reused yet, so the chain is strictly older. */
            while (cand != 0 && chain-- > 0 && pos - (cand - 1) <= IMG__WINDOW) {
                size_t c = cand - 1, len = 0;
                while (len < max_len && src[c + len] == src[pos + len]) len++;
                if (len > best_len) {
                    best_len = len;
                    best_dist = pos - c;
                    if (len == max_len) break;
                }
                cand = prev[c % IMG__WINDOW];
            }
        }
        /* A 3-byte match farther than 4096 bytes (23-25 bits) gains nothing over three literals
           (24-27 bits): zlib skips those too. */
        if (best_len >= 4 || (best_len == 3 && best_dist <= 4096)) {
            img__put_match(&bw, (int)best_len, (int)best_dist);
            step = best_len;
        } else {
            img__put_symbol(&bw, src[pos]);
            step = 1;
        }
        for (i = 0; i < step; i++, pos++) { /* every consumed position joins the chains */
            if (n - pos >= 3) {
                uint32_t h = img__hash3(src + pos);
                prev[pos % IMG__WINDOW] = head[h];
                head[h] = pos + 1;
            }
        }
    }
    img__put_symbol(&bw, 256);                           /* end of block */
    if (bw.nacc > 0) img__put_bits(&bw, 0, 8 - bw.nacc); /* pad to a byte boundary */
    adler = img__adler32(src, n); /* RFC 1950 2.2: ADLER32, most significant byte first */
    for (i = 0; i < 4; i++) img__put_bits(&bw, (adler >> (24 - 8 * i)) & 0xFFu, 8);
    free(head);
    free(prev);
    if (bw.full) {
        free(bw.buf);
        return NULL;
    }
    *out_len = bw.len;
    return bw.buf;
}

/* CRC-32 of PNG 5.5 (polynomial 0xEDB88320, reflected, pre- and post-inverted), table-driven. */
typedef struct img__png {
    FILE* f;
    uint32_t crc_table[256];
    int failed;
} img__png;

static void img__png_bytes(img__png* png, const unsigned char* p, size_t n, uint32_t* crc) {
    size_t i;
    if (n > 0 && fwrite(p, 1, n, png->f) != n) png->failed = 1;
    for (i = 0; i < n; i++) *crc = png->crc_table[(*crc ^ p[i]) & 0xFFu] ^ (*crc >> 8);
}

static void img__be32(unsigned char* p, uint32_t v) {
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* PNG 5.3 chunk layout: length (4 bytes, big-endian, data only), type, data, and a CRC over the
   type and data. */
static void img__png_chunk(img__png* png, const char* type, const unsigned char* data, size_t n) {
    unsigned char word[4];
    uint32_t crc = 0xFFFFFFFFu, unused = 0;
    img__be32(word, (uint32_t)n);
    img__png_bytes(png, word, 4, &unused);
    img__png_bytes(png, (const unsigned char*)type, 4, &crc);
    img__png_bytes(png, data, n, &crc);
    img__be32(word, crc ^ 0xFFFFFFFFu);
    img__png_bytes(png, word, 4, &unused);
}

#define IMG__IDAT_MAX 65536 /* the zlib stream is split over IDAT chunks of at most this size */

/* Writes im as an 8-bit RGB PNG (colour type 2, no interlace). */
IMGDEF int img_write_png(const img* im, const char* path) {
    static const unsigned char signature[8] = {137, 80, 78, 71, 13, 10, 26, 10}; /* PNG 5.2 */
    unsigned char ihdr[13];
    unsigned char *raw, *z;
    size_t stride, raw_len, z_len = 0, off;
    img__png png;
    uint32_t k, c, unused = 0;
    int y;
    if (!im || !im->rgb || im->w <= 0 || im->h <= 0 || !path) return -1;
    stride = (size_t)im->w * 3;
    if (stride + 1 > (size_t)-1 / 2 / (size_t)im->h) return -1; /* keeps every size below fit */
    raw_len = (stride + 1) * (size_t)im->h;
    raw = (unsigned char*)malloc(raw_len);
    if (!raw) return -1;
    /* PNG 9.2: each scanline is a filter-type byte followed by the filtered bytes; Sub(x) =
       Raw(x) - Raw(x - 3) for 3-byte pixels. PNG 12.8 suggests choosing per row the filter whose
       output has the smallest sum of absolute values (bytes read as signed): None or Sub here. */
    for (y = 0; y < im->h; y++) {
        const unsigned char* in = im->rgb + (size_t)y * stride;
        unsigned char* out = raw + (size_t)y * (stride + 1);
        size_t x;
        unsigned long cost_none = 0, cost_sub = 0;
        for (x = 0; x < stride; x++) {
            unsigned d = (unsigned char)(in[x] - (x >= 3 ? in[x - 3] : 0));
            cost_none += in[x] < 128 ? in[x] : 256u - in[x];
            cost_sub += d < 128 ? d : 256u - d;
        }
        out[0] = cost_sub < cost_none ? 1 : 0;
        for (x = 0; x < stride; x++)
            out[1 + x] = out[0] == 1 ? (unsigned char)(in[x] - (x >= 3 ? in[x - 3] : 0)) : in[x];
    }
    z = img__zlib(raw, raw_len, &z_len);
    free(raw);
    if (!z) return -1;
    for (k = 0; k < 256; k++) { /* PNG 5.5 / Annex D CRC table */
        for (c = k, y = 0; y < 8; y++) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        png.crc_table[k] = c;
    }
    png.failed = 0;
    png.f = fopen(path, "wb");
    if (!png.f) {
        free(z);
        return -1;
    }
    img__png_bytes(&png, signature, 8, &unused);
    img__be32(ihdr, (uint32_t)im->w); /* PNG 11.2.2 IHDR */
    img__be32(ihdr + 4, (uint32_t)im->h);
    ihdr[8] = 8;   /* bit depth */
    ihdr[9] = 2;   /* colour type 2: truecolour RGB */
    ihdr[10] = 0;  /* compression method 0: zlib deflate (PNG 10.1) */
    ihdr[11] = 0;  /* filter method 0: the five adaptive filters (PNG 9.1) */
    ihdr[12] = 0;  /* no interlace */
    img__png_chunk(&png, "IHDR", ihdr, 13);
    for (off = 0; off < z_len; off += IMG__IDAT_MAX) /* PNG 11.2.4: IDATs are concatenated */
        img__png_chunk(&png, "IDAT", z + off,
                       z_len - off < IMG__IDAT_MAX ? z_len - off : IMG__IDAT_MAX);
    img__png_chunk(&png, "IEND", NULL, 0); /* PNG 11.2.5 */
    free(z);
    if (fclose(png.f) != 0) png.failed = 1;
    if (png.failed) remove(path);
    return png.failed ? -1 : 0;
}

/* Binary PPM (P6): the simplest lossless fallback every image tool reads. */
IMGDEF int img_write_ppm(const img* im, const char* path) {
    FILE* f;
    size_t n;
    int ok;
    if (!im || !im->rgb || im->w <= 0 || im->h <= 0 || !path) return -1;
    f = fopen(path, "wb");
    if (!f) return -1;
    n = (size_t)im->w * (size_t)im->h * 3;
    ok = fprintf(f, "P6\n%d %d\n255\n", im->w, im->h) > 0 && fwrite(im->rgb, 1, n, f) == n;
    if (fclose(f) != 0) ok = 0;
    if (!ok) remove(path);
    return ok ? 0 : -1;
}

#endif /* SPH_EXAMPLES_IMAGE_H */
