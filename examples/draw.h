/* examples/draw.h - particle pictures and output files for the sph.h examples (2D worlds).

   On top of examples/image.h: a picture of a box of the world with the particles as discs
   (fluid coloured by a value or a fixed colour, walls grey), a caption line and, below it, a
   colour bar with its range and unit (or swatches for categories), written as a PNG. Include it
   after sph.h; like image.h every function is static.

     draw d;
     if (draw_begin(&d, w, x0, y0, x1, y1, 1000)) {     world box [x0,x1] x [y0,y1], 1000 px wide
         draw_walls(&d, w, -1, 140, 140, 140);           boundary particles (of one body or all)
         draw_fluid_speed(&d, w, vmax);                  fluid coloured by |v| / vmax, bar 0..vmax
         draw_finish(&d, path, "t = 0.50 s");            caption + bar, PNG, frees; 0 on success
     }

   draw_colorbar(&d, "speed |v| [m/s]", lo, hi) sets the bar of a custom colouring (draw_disc with
   draw_color), draw_swatch(&d, "heavy 1.8", r, g, b) adds a category instead. draw_canvas gives
   an empty picture for a custom layout that still gets the caption band. draw_fopen opens
   DIR/NAME and says what to do when DIR does not exist; draw_frame_path makes DIR/NAME_0007.png. */
#ifndef SPH_EXAMPLES_DRAW_H
#define SPH_EXAMPLES_DRAW_H

#include "examples/image.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define DRAW_BAND 56   /* caption band height [px]: a caption line and a colour-bar line */
#define DRAW_SWATCHES 4

typedef struct draw {
    img im;
    int plot_h;           /* rows of the picture above the band                             */
    double x0, y0, scale; /* world point at the picture's lower left [m]; pixels per metre */
    double radius;        /* disc radius [px]: 0.62 spacings                                */
    const char* bar_name; /* colour bar: name and unit, NULL for none                       */
    double bar_lo, bar_hi;
    int nswatch;
    const char* swatch_name[DRAW_SWATCHES];
    unsigned char swatch_rgb[DRAW_SWATCHES][3];
} draw;

static void draw__reset(draw* d) {
    d->bar_name = NULL;
    d->bar_lo = 0;
    d->bar_hi = 1;
    d->nswatch = 0;
}

/* An empty picture of width x plot_h pixels plus the band; 1 on success, 0 on failure. */
IMGDEF int draw_canvas(draw* d, int width, int plot_h) {
    memset(d, 0, sizeof(*d));
    draw__reset(d);
    d->plot_h = plot_h;
    d->scale = 1;
    if (!img_init(&d->im, width, plot_h + DRAW_BAND)) return 0;
    img_fill(&d->im, 250, 250, 248);
    img_rect(&d->im, 0, plot_h, width, plot_h + DRAW_BAND, 255, 255, 255);
    return 1;
}

/* A picture of the world box [x0, x1] x [y0, y1] [m], width pixels wide (the height follows). */
IMGDEF int draw_begin(draw* d, const sph_world* w, double x0, double y0, double x1, double y1,
                      int width) {
    const double scale = width / (x1 - x0);
    if (!(x1 > x0) || !(y1 > y0) || !draw_canvas(d, width, (int)((y1 - y0) * scale + 0.5)))
        return 0;
    d->x0 = x0;
    d->y0 = y0;
    d->scale = scale;
    d->radius = 0.62 * (double)w->dx * scale;
    return 1;
}

/* A world point [m] to pixel coordinates. */
IMGDEF void draw_to_px(const draw* d, double x, double y, double* px, double* py) {
    *px = (x - d->x0) * d->scale;
    *py = d->plot_h - (y - d->y0) * d->scale;
}

IMGDEF void draw_disc(draw* d, double x, double y, unsigned char r, unsigned char g,
                      unsigned char b) {
    double px, py;
    draw_to_px(d, x, y, &px, &py);
    img_disc(&d->im, px, py, d->radius, r, g, b);
}

/* The colour of value v on the colour bar's scale (clamped to its range). */
IMGDEF void draw_color(const draw* d, double v, unsigned char* rgb) {
    img_colormap((v - d->bar_lo) / (d->bar_hi - d->bar_lo), rgb);
}

IMGDEF void draw_colorbar(draw* d, const char* name_and_unit, double lo, double hi) {
    d->bar_name = name_and_unit;
    d->bar_lo = lo;
    d->bar_hi = hi > lo ? hi : lo + 1;
}

IMGDEF void draw_swatch(draw* d, const char* name, unsigned char r, unsigned char g,
                        unsigned char b) {
    if (d->nswatch >= DRAW_SWATCHES) return;
    d->swatch_name[d->nswatch] = name;
    d->swatch_rgb[d->nswatch][0] = r;
    d->swatch_rgb[d->nswatch][1] = g;
    d->swatch_rgb[d->nswatch][2] = b;
    ++d->nswatch;
}

/* Boundary particles of body tag `body` (-1: all), in one colour. */
IMGDEF void draw_walls(draw* d, const sph_world* w, int body, unsigned char r, unsigned char g,
                       unsigned char b) {
    size_t i;
    for (i = 0; i < w->nb; ++i)
        if (body < 0 || w->b_body[i] == body)
            draw_disc(d, (double)w->b_x[2 * i], (double)w->b_x[2 * i + 1], r, g, b);
}

/* Fluid particles coloured by speed, 0 .. vmax [m/s]; sets the colour bar to match. */
IMGDEF void draw_fluid_speed(draw* d, const sph_world* w, double vmax) {
    size_t i;
    draw_colorbar(d, "speed |v| [m/s]", 0, vmax);
    for (i = 0; i < w->n; ++i) {
        const double vx = (double)w->v[2 * i], vy = (double)w->v[2 * i + 1];
        unsigned char c[3];
        draw_color(d, sqrt(vx * vx + vy * vy), c);
        draw_disc(d, (double)w->x[2 * i], (double)w->x[2 * i + 1], c[0], c[1], c[2]);
    }
}

/* A number for the bar's ends: 3 significant digits, no exponent for everyday ranges. */
static void draw__number(char* buf, size_t size, double v) {
    const double a = fabs(v);
    if (a != 0 && (a < 1e-3 || a >= 1e6)) snprintf(buf, size, "%.2e", v);
    else if (a >= 100) snprintf(buf, size, "%.0f", v);
    else snprintf(buf, size, "%.3g", v);
}

/* Draws the caption and the colour bar (or swatches) in the band, writes the PNG, frees the
   picture. 0 on success, -1 (with a message on stderr) if the file could not be written. */
IMGDEF int draw_finish(draw* d, const char* path, const char* caption) {
    const int y_cap = d->plot_h + 6, y_bar = d->plot_h + 32, ink = 30;
    const int ts = d->im.w >= 600 ? 2 : 1; /* text scale of the bar line */
    int x = 8, rc = 0, k;
    if (caption) img_text(&d->im, 8, y_cap, 2, caption, ink, ink, ink);
    if (d->bar_name) { /* "speed |v| [m/s]  0 [=======] 4.43" */
        const int bar_w = d->im.w >= 600 ? 240 : 120;
        char lo[32], hi[32];
        draw__number(lo, sizeof lo, d->bar_lo);
        draw__number(hi, sizeof hi, d->bar_hi);
        x = img_text(&d->im, x, y_bar, ts, d->bar_name, ink, ink, ink) + 10;
        x = img_text(&d->im, x, y_bar, ts, lo, ink, ink, ink) + 6;
        for (k = 0; k < bar_w; ++k) {
            unsigned char c[3];
            img_colormap((double)k / (bar_w - 1), c);
            img_rect(&d->im, x + k, y_bar - 1, x + k + 1, y_bar + 7 * ts + 1, c[0], c[1], c[2]);
        }
        x = img_text(&d->im, x + bar_w + 6, y_bar, ts, hi, ink, ink, ink) + 16;
    }
    for (k = 0; k < d->nswatch; ++k) {
        img_disc(&d->im, x + 3 * ts + 2, y_bar + 3.5 * ts, 3 * ts + 1, d->swatch_rgb[k][0],
                 d->swatch_rgb[k][1], d->swatch_rgb[k][2]);
        x = img_text(&d->im, x + 6 * ts + 8, y_bar, ts, d->swatch_name[k], ink, ink, ink) + 14;
    }
    if (img_write_png(&d->im, path) != 0) {
        fprintf(stderr, "could not write %s\n", path);
        rc = -1;
    }
    img_free(&d->im);
    return rc;
}

/* DIR/NAME_FRAME.png (frame with 4 digits) into buf. */
IMGDEF void draw_frame_path(char* buf, size_t size, const char* dir, const char* name, int frame) {
    snprintf(buf, size, "%s/%s_%04d.png", dir, name, frame);
}

/* Opens DIR/NAME for writing; on failure says how to create the directory and returns NULL. */
IMGDEF FILE* draw_fopen(const char* dir, const char* name) {
    char path[1024];
    FILE* f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "w");
    if (!f) fprintf(stderr, "cannot write %s (create the directory first: mkdir -p %s)\n", path, dir);
    return f;
}

#endif /* SPH_EXAMPLES_DRAW_H */
