/* tests/png_check.c - writes test images with examples/image.h for tests/check_png.py to verify.

   Build and run (from the repository root):

       mkdir -p build
       gcc -O2 -std=c99 -Wall -Wextra -Wpedantic -Wshadow tests/png_check.c -o build/png_check -lm
       ./build/png_check build && python3 tests/check_png.py build

   `build/png_check DIR` writes into DIR, for each image NAME, NAME.png and NAME.rgb (the raw RGB
   bytes, w * h * 3, row-major, top row first); the pattern is also written as pattern.ppm.
   tests/check_png.py DIR then decodes every NAME.png / NAME.ppm that has a NAME.rgb beside it
   and compares the pixels byte for byte. The images:

     pattern    10922 x 40: each row is 1 + 3 * 10922 = 32767 bytes of PNG scanline, so the same
                pixel one row up is 32767 bytes back (just inside DEFLATE's 32 KiB window) and two
                rows up 65534 bytes back (outside it). Gradients, flat bands (long runs), discs of
                many sizes (some clipped), text at scales 1-3, xorshift noise (literals), a noise
                block repeated 24000 bytes further along the same rows, and noise rows each shifted
                by one byte from the row above so that a match at exactly distance 32768 exists.
     particles  800 x 600: about 4000 anti-aliased particles on a flat background, a label and
                a colour bar: what the examples write. Its compression ratio is the one to quote.
     tiny       1 x 1.
     small      3 x 2, six different colours.

   It also checks a few API edge cases (bad sizes, unwritable paths, clamped colour map) and exits
   non-zero if anything fails. */
#include "../examples/image.h"

#include <time.h>

static int failures;

static void expect(int cond, const char* what) {
    if (!cond) {
        printf("png_check: FAILED: %s\n", what);
        failures++;
    }
}

/* xorshift32 (Marsaglia 2003): a fixed, platform-independent byte sequence. */
static uint32_t rng_state;
static uint32_t rng_next(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static void path_join(char* out, size_t cap, const char* dir, const char* name) {
    size_t n = strlen(dir);
    snprintf(out, cap, "%s%s%s", dir, (n > 0 && dir[n - 1] == '/') ? "" : "/", name);
}

/* Writes DIR/NAME.png and DIR/NAME.rgb and prints the sizes and the ratio. */
static void save(const img* im, const char* dir, const char* name) {
    char path[4096], file[256];
    FILE* f;
    size_t raw = (size_t)im->w * (size_t)im->h * 3;
    long png_size = -1;
    clock_t t0;
    double ms;
    int rc;
    snprintf(file, sizeof file, "%s.png", name);
    path_join(path, sizeof path, dir, file);
    t0 = clock();
    rc = img_write_png(im, path);
    ms = 1000.0 * (double)(clock() - t0) / CLOCKS_PER_SEC;
    expect(rc == 0, "img_write_png returns 0");
    f = fopen(path, "rb");
    if (f) {
        if (fseek(f, 0, SEEK_END) == 0) png_size = ftell(f);
        fclose(f);
    }
    printf("wrote %s  %dx%d  raw %lu bytes  png %ld bytes  file/raw %.4f  (%.1f ms)\n", path, im->w,
           im->h, (unsigned long)raw, png_size, (double)png_size / (double)raw, ms);
    snprintf(file, sizeof file, "%s.rgb", name);
    path_join(path, sizeof path, dir, file);
    f = fopen(path, "wb");
    expect(f && fwrite(im->rgb, 1, raw, f) == raw, "write the .rgb file");
    if (f) expect(fclose(f) == 0, "close the .rgb file");
}

static void draw_pattern(img* im) {
    const int w = im->w, h = im->h;
    const size_t stride = (size_t)w * 3;
    unsigned char c[3];
    int x, y, i;
    /* Background: a horizontal gradient with a per-row green level. */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++)
            img_put(im, x, y, (unsigned char)(x * 255 / (w - 1)), (unsigned char)(40 + 4 * y),
                    (unsigned char)(255 - x * 255 / (w - 1)));
    /* Flat bands and a colour-map strip (long runs, short repeats). */
    img_rect(im, 200, 2, 900, 38, 20, 24, 32);
    for (x = 0; x < 1024; x++) {
        img_colormap(x / 1023.0, c);
        img_rect(im, 5000 + x, 30, 5001 + x, 40, c[0], c[1], c[2]);
    }
    img_rect(im, 7000, 38, 6000, 4, 250, 250, 250); /* reversed corners */
    img_rect(im, -50, -50, 30, 6, 255, 0, 0);       /* clipped at the top-left */
    img_rect(im, w - 10, h - 3, w + 100, h + 100, 0, 0, 255);
    img_rect(im, w + 5, 0, w + 50, h, 0, 255, 0); /* entirely outside: draws nothing */
    /* Discs: sub-pixel, small, large, clipped on every side, a non-finite centre. */
    for (i = 0; i < 60; i++) {
        double r = 0.2 + 0.35 * i;
        img_colormap(i / 59.0, c);
        img_disc(im, 220.0 + 23.0 * i + 0.37 * i, 20.3, r < 17.0 ? r : 17.0, c[0], c[1], c[2]);
    }
    img_disc(im, -3.0, 20.0, 12.0, 255, 255, 255);
    img_disc(im, w + 2.5, 10.0, 9.0, 255, 255, 0);
    img_disc(im, 3000.0, -4.0, 10.0, 0, 255, 255);
    img_disc(im, 3100.0, h + 4.0, 10.0, 255, 0, 255);
    img_disc(im, nan(""), 5.0, 5.0, 1, 2, 3);    /* NaN centre: draws nothing */
    img_disc(im, -1e300, 20.0, 1e30, 9, 9, 9); /* far outside: nothing, no overflow */
    img_disc(im, 3500.0, 480.0, 470.5, 9, 9, 9); /* a large disc's clipped cap */
    img_rect(im, 3400, 0, 3600, h, 30, 30, 30);
    /* Text at three scales, the whole character set, and a line break; partly off the edge. */
    img_text(im, 4, 8, 1, "t = 0.50 s  front Z = 1.83", 255, 255, 255);
    img_text(im, 2000, 2, 3, "Dam break (2D)", 255, 255, 255);
    img_text(im, 2400, 2, 1,
             " !\"#$%&'()*+,-./0123456789:;<=>?@ABCDEFGHIJKLMNOPQRSTUVWXYZ[\\]^_`\n"
             "abcdefghijklmnopqrstuvwxyz{|}~ \t\x7f\x80\xff",
             0, 0, 0);
    img_text(im, 3620, 10, 2, "rho/rho0 - 1 = +0.3% _q(y)", 255, 200, 0);
    img_text(im, w - 40, 12, 2, "clipped", 255, 255, 255);
    /* Noise (literals), repeated 8000 pixels = 24000 bytes further along the same rows. */
    for (y = 8; y < 24; y++) {
        rng_state = 0x9E3779B9u + (uint32_t)y;
        for (x = 1000; x < 1400; x++) {
            uint32_t v = rng_next();
            img_put(im, x, y, (unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16));
            img_put(im, x + 8000, y, (unsigned char)v, (unsigned char)(v >> 8),
                    (unsigned char)(v >> 16));
        }
    }
    /* Noise rows 26..33: the same 1200 bytes in each, one byte further right per row, so in the
       filtered stream each copy starts 32767 + 1 = 32768 bytes after the one above it. */
    for (y = 26; y < 34; y++) {
        unsigned char* row = im->rgb + (size_t)y * stride;
        rng_state = 0x12345678u;
        for (i = 0; i < 1200; i++) row[3 * 4000 + (y - 26) + i] = (unsigned char)(rng_next() >> 7);
    }
}

static void draw_particles(img* im) {
    unsigned char c[3];
    int i, j, x;
    img_fill(im, 245, 245, 240);
    img_rect(im, 40, 60, 760, 64, 60, 60, 60); /* tank: top edge left open, walls and floor */
    img_rect(im, 40, 60, 44, 560, 60, 60, 60);
    img_rect(im, 756, 60, 760, 560, 60, 60, 60);
    img_rect(im, 40, 556, 760, 560, 60, 60, 60);
    rng_state = 2463534242u;
    for (j = 0; j < 50; j++) {
        for (i = 0; i < 80; i++) {
            double jx = (double)(rng_next() % 1000) / 1000.0 - 0.5;
            double jy = (double)(rng_next() % 1000) / 1000.0 - 0.5;
            double px = 50.0 + 6.1 * i + 0.3 * jx + (j % 2) * 3.05;
            double py = 550.0 - 5.3 * j + 0.3 * jy;
            img_colormap((double)j / 49.0 * (0.4 + 0.6 * (double)i / 79.0), c);
            img_disc(im, px, py, 2.6, c[0], c[1], c[2]);
        }
    }
    for (x = 0; x < 300; x++) { /* colour bar */
        img_colormap(x / 299.0, c);
        img_rect(im, 460 + x, 20, 461 + x, 36, c[0], c[1], c[2]);
    }
    img_text(im, 460, 40, 1, "0", 40, 40, 40);
    img_text(im, 610 - img_text_width(1, "|v| / v_max") / 2, 40, 1, "|v| / v_max", 40, 40, 40);
    img_text(im, 760 - img_text_width(1, "1") + 1, 40, 1, "1", 40, 40, 40);
    img_text(im, 44, 20, 2, "t = 0.50 s  front Z = 1.83", 20, 20, 20);
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : "build";
    char path[4096];
    img im, bad;
    unsigned char c[3], prev[3];
    int i;

    /* API edge cases. */
    expect(!img_init(&bad, 0, 5) && bad.rgb == NULL && bad.w == 0, "img_init rejects width 0");
    expect(!img_init(&bad, 5, -1) && bad.rgb == NULL, "img_init rejects a negative height");
    img_free(&bad); /* freeing an empty image is harmless */
    img_colormap(-1.0, c);
    img_colormap(0.0, prev);
    expect(memcmp(c, prev, 3) == 0, "img_colormap clamps t < 0");
    img_colormap(2.0, c);
    img_colormap(1.0, prev);
    expect(memcmp(c, prev, 3) == 0, "img_colormap clamps t > 1");
    for (i = 0; i <= 64; i++) { /* luma rises monotonically (perceptual ordering) */
        double l1, l0 = 0.2126 * prev[0] + 0.7152 * prev[1] + 0.0722 * prev[2];
        img_colormap(i / 64.0, c);
        l1 = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        if (i > 0) expect(l1 > l0, "img_colormap luma increases with t");
        memcpy(prev, c, 3);
    }
    expect(img_text_width(2, "ab\nabcd\n") == 4 * 6 * 2, "img_text_width of the longest line");

    /* The 10922-pixel-wide pattern (see the top of this file). */
    if (!img_init(&im, 10922, 40)) return 1;
    draw_pattern(&im);
    save(&im, dir, "pattern");
    path_join(path, sizeof path, dir, "pattern.ppm");
    expect(img_write_ppm(&im, path) == 0, "img_write_ppm returns 0");
    path_join(path, sizeof path, dir, "no-such-directory/pattern.png");
    expect(img_write_png(&im, path) != 0, "img_write_png fails on an unwritable path");
    expect(img_write_ppm(&im, path) != 0, "img_write_ppm fails on an unwritable path");
    img_free(&im);
    expect(img_write_png(&im, path) != 0, "img_write_png rejects an empty image");

    if (!img_init(&im, 800, 600)) return 1;
    draw_particles(&im);
    save(&im, dir, "particles");
    img_free(&im);

    if (!img_init(&im, 1, 1)) return 1;
    img_fill(&im, 12, 200, 255);
    save(&im, dir, "tiny");
    img_free(&im);

    if (!img_init(&im, 3, 2)) return 1;
    img_put(&im, 0, 0, 255, 0, 0);
    img_put(&im, 1, 0, 0, 255, 0);
    img_put(&im, 2, 0, 0, 0, 255);
    img_put(&im, 0, 1, 255, 255, 255);
    img_put(&im, 1, 1, 128, 128, 128);
    img_put(&im, 2, 1, 1, 2, 3);
    save(&im, dir, "small");
    img_free(&im);

    if (failures) {
        printf("png_check: %d failure(s)\n", failures);
        return 1;
    }
    printf("png_check: all images written to %s\n", dir);
    return 0;
}
