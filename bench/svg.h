/* bench/svg.h - a small SVG line/point chart writer (no dependencies beyond libc and libm).

   Used by bench/ and tests/ to draw SPH results against reference solutions:

       svg_chart ch;
       svg_begin(&ch, "Shock tube, t = 0.5 ms", "x [m]", "p [MPa]");
       svg_series(&ch, x_exact, p_exact, n, SVG_LINE, "exact");
       svg_series(&ch, x_sph, p_sph, m, SVG_DOTS, "SPH");
       svg_write(&ch, "out/shock.svg");   (axes span all series, with rounded ticks)
       svg_free(&ch);

   Series are copied, so the caller's arrays may go away before svg_write. */
#ifndef SPH_BENCH_SVG_H
#define SPH_BENCH_SVG_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define SVG_FN static __attribute__((unused)) /* a program uses only some of them */
#else
#define SVG_FN static
#endif

enum { SVG_LINE = 0, SVG_DOTS = 1, SVG_DASHED = 2, SVG_LINE_MARKS = 3 };
#define SVG_MAX_SERIES 12

typedef struct svg_series_t {
    double* x;
    double* y;
    size_t n;
    int style;
    char label[64];
} svg_series_t;

typedef struct svg_chart {
    char title[128], xlabel[64], ylabel[64];
    svg_series_t s[SVG_MAX_SERIES];
    int ns;
    int fix_x, fix_y; /* set by svg_range: axis limits given instead of fitted */
    int log_x, log_y; /* set by svg_log: logarithmic axes (decade ticks; values <= 0 skipped) */
    double x0, x1, y0, y1;
} svg_chart;

SVG_FN void svg_begin(svg_chart* c, const char* title, const char* xlabel, const char* ylabel) {
    memset(c, 0, sizeof(*c));
    snprintf(c->title, sizeof c->title, "%s", title);
    snprintf(c->xlabel, sizeof c->xlabel, "%s", xlabel);
    snprintf(c->ylabel, sizeof c->ylabel, "%s", ylabel);
}

/* Fixes the x (axis 0) or y (axis 1) range instead of fitting it to the data. */
SVG_FN void svg_range(svg_chart* c, int axis, double lo, double hi) {
    if (axis == 0) { c->fix_x = 1; c->x0 = lo; c->x1 = hi; }
    else { c->fix_y = 1; c->y0 = lo; c->y1 = hi; }
}

/* Makes the x (axis 0) or y (axis 1) axis logarithmic; svg_range limits stay in data units. */
SVG_FN void svg_log(svg_chart* c, int axis) {
    if (axis == 0) c->log_x = 1;
    else c->log_y = 1;
}

/* Adds a series (copied); returns 0, or -1 if full or out of memory. */
SVG_FN int svg_series(svg_chart* c, const double* x, const double* y, size_t n, int style,
                      const char* label) {
    svg_series_t* s;
    if (c->ns >= SVG_MAX_SERIES) return -1;
    s = &c->s[c->ns];
    s->x = (double*)malloc((n ? n : 1) * sizeof(double));
    s->y = (double*)malloc((n ? n : 1) * sizeof(double));
    if (!s->x || !s->y) { free(s->x); free(s->y); s->x = s->y = NULL; return -1; }
    if (n) { memcpy(s->x, x, n * sizeof(double)); memcpy(s->y, y, n * sizeof(double)); }
    s->n = n;
    s->style = style;
    snprintf(s->label, sizeof s->label, "%s", label);
    ++c->ns;
    return 0;
}

SVG_FN void svg_free(svg_chart* c) {
    int k;
    for (k = 0; k < c->ns; ++k) { free(c->s[k].x); free(c->s[k].y); }
    c->ns = 0;
}

/* A "nice" tick step (1, 2 or 5 times a power of ten) for about `count` ticks over span. */
SVG_FN double svg_tick(double span, int count) {
    double raw = span / count, p = pow(10, floor(log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

SVG_FN void svg_escape(FILE* f, const char* s) {
    for (; *s; ++s) {
        if (*s == '<') fputs("&lt;", f);
        else if (*s == '>') fputs("&gt;", f);
        else if (*s == '&') fputs("&amp;", f);
        else fputc(*s, f);
    }
}

/* Writes the chart; returns 0 on success, -1 if the file cannot be written. */
SVG_FN int svg_write(const svg_chart* c, const char* path) {
    static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                   "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
                                   "#000000", "#aec7e8"};
    const double W = 720, H = 440, L = 78, R = 170, T = 40, B = 56;
    const double pw = W - L - R, ph = H - T - B;
    double x0 = c->x0, x1 = c->x1, y0 = c->y0, y1 = c->y1, t, step;
    FILE* f;
    int k;
    size_t i;
#define SVG_TX(v) (c->log_x ? ((v) > 0 ? log10(v) : NAN) : (v))
#define SVG_TY(v) (c->log_y ? ((v) > 0 ? log10(v) : NAN) : (v))
    if (c->fix_x) { x0 = SVG_TX(c->x0); x1 = SVG_TX(c->x1); }
    if (c->fix_y) { y0 = SVG_TY(c->y0); y1 = SVG_TY(c->y1); }
    if (!c->fix_x || !c->fix_y) { /* fit the free axes to the finite data */
        double ax0 = 1e300, ax1 = -1e300, ay0 = 1e300, ay1 = -1e300;
        for (k = 0; k < c->ns; ++k)
            for (i = 0; i < c->s[k].n; ++i) {
                const double xv = SVG_TX(c->s[k].x[i]), yv = SVG_TY(c->s[k].y[i]);
                if (!isfinite(xv) || !isfinite(yv)) continue;
                if (c->fix_x && (xv < x0 || xv > x1)) continue;
                ax0 = fmin(ax0, xv); ax1 = fmax(ax1, xv);
                ay0 = fmin(ay0, yv); ay1 = fmax(ay1, yv);
            }
        if (ax0 > ax1) { ax0 = 0; ax1 = 1; ay0 = 0; ay1 = 1; }
        if (!c->fix_x) { x0 = ax0; x1 = ax1; }
        if (!c->fix_y) {
            const double pad = 0.05 * (ay1 - ay0 > 0 ? ay1 - ay0 : fabs(ay1) + 1);
            y0 = ay0 - pad; y1 = ay1 + pad;
        }
        if (c->log_x && !c->fix_x) { x0 = floor(x0 + 1e-9); x1 = ceil(x1 - 1e-9); }
        if (c->log_y && !c->fix_y) { y0 = floor(y0 + 0.05); y1 = ceil(y1 - 0.05); }
    }
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    f = fopen(path, "w");
    if (!f) return -1;
#define SVG_X(v) (L + (SVG_TX(v) - x0) / (x1 - x0) * pw)
#define SVG_Y(v) (T + ph - (SVG_TY(v) - y0) / (y1 - y0) * ph)
#define SVG_PX(t) (L + ((t) - x0) / (x1 - x0) * pw) /* from axis units */
#define SVG_PY(t) (T + ph - ((t) - y0) / (y1 - y0) * ph)
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
               "viewBox=\"0 0 %g %g\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H, W, H);
    fprintf(f, "<rect width=\"%g\" height=\"%g\" fill=\"white\"/>\n", W, H);
    fprintf(f, "<text x=\"%g\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">", L + pw / 2);
    svg_escape(f, c->title);
    fprintf(f, "</text>\n<defs><clipPath id=\"plot\"><rect x=\"%g\" y=\"%g\" width=\"%g\" "
               "height=\"%g\"/></clipPath></defs>\n", L, T, pw, ph);
    /* grid and ticks */
    step = c->log_x && x1 - x0 >= 1 ? 1 : svg_tick(x1 - x0, 7);
    for (t = ceil(x0 / step) * step; t <= x1 + 1e-9 * step; t += step) {
        const double px = SVG_PX(t), tv = fabs(t) < 1e-12 * step ? 0 : t;
        fprintf(f, "<line x1=\"%.2f\" y1=\"%g\" x2=\"%.2f\" y2=\"%g\" stroke=\"#e5e5e5\"/>\n", px, T, px, T + ph);
        fprintf(f, "<text x=\"%.2f\" y=\"%g\" text-anchor=\"middle\">%g</text>\n", px, T + ph + 16,
                c->log_x ? pow(10, tv) : tv);
        if (c->log_x && step == 1) { /* minor lines at 2..9 */
            int m;
            for (m = 2; m <= 9; ++m)
                if (t + log10(m) < x1)
                    fprintf(f, "<line x1=\"%.2f\" y1=\"%g\" x2=\"%.2f\" y2=\"%g\" stroke=\"#f3f3f3\"/>\n",
                            SVG_PX(t + log10(m)), T, SVG_PX(t + log10(m)), T + ph);
        }
    }
    step = c->log_y && y1 - y0 >= 1 ? 1 : svg_tick(y1 - y0, 6);
    for (t = ceil(y0 / step) * step; t <= y1 + 1e-9 * step; t += step) {
        const double py = SVG_PY(t), tv = fabs(t) < 1e-12 * step ? 0 : t;
        fprintf(f, "<line x1=\"%g\" y1=\"%.2f\" x2=\"%g\" y2=\"%.2f\" stroke=\"#e5e5e5\"/>\n", L, py, L + pw, py);
        fprintf(f, "<text x=\"%g\" y=\"%.2f\" text-anchor=\"end\">%.6g</text>\n", L - 6, py + 4,
                c->log_y ? pow(10, tv) : tv);
        if (c->log_y && step == 1) {
            int m;
            for (m = 2; m <= 9; ++m)
                if (t + log10(m) < y1)
                    fprintf(f, "<line x1=\"%g\" y1=\"%.2f\" x2=\"%g\" y2=\"%.2f\" stroke=\"#f3f3f3\"/>\n",
                            L, SVG_PY(t + log10(m)), L + pw, SVG_PY(t + log10(m)));
        }
    }
    fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n",
            L, T, pw, ph);
    fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">", L + pw / 2, H - 14);
    svg_escape(f, c->xlabel);
    fprintf(f, "</text>\n<text x=\"18\" y=\"%g\" text-anchor=\"middle\" transform=\"rotate(-90 18 %g)\">",
            T + ph / 2, T + ph / 2);
    svg_escape(f, c->ylabel);
    fprintf(f, "</text>\n");
    /* series */
    for (k = 0; k < c->ns; ++k) {
        const svg_series_t* s = &c->s[k];
        const char* col = colors[k % 12];
        if (s->style == SVG_DOTS || s->style == SVG_LINE_MARKS) {
            fprintf(f, "<g fill=\"%s\" clip-path=\"url(#plot)\">\n", col);
            for (i = 0; i < s->n; ++i)
                if (isfinite(SVG_TX(s->x[i])) && isfinite(SVG_TY(s->y[i])))
                    fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%s\"/>\n", SVG_X(s->x[i]),
                            SVG_Y(s->y[i]), s->style == SVG_DOTS ? "1.8" : "3.5");
            fprintf(f, "</g>\n");
        }
        if (s->style != SVG_DOTS) {
            int open = 0;
            for (i = 0; i < s->n; ++i) {
                if (!isfinite(SVG_TX(s->x[i])) || !isfinite(SVG_TY(s->y[i]))) {
                    if (open) fprintf(f, "\"/>\n");
                    open = 0;
                    continue;
                }
                if (!open) {
                    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\"%s "
                               "clip-path=\"url(#plot)\" points=\"",
                            col, s->style == SVG_DASHED ? " stroke-dasharray=\"5,3\"" : "");
                    open = 1;
                }
                fprintf(f, "%.2f,%.2f ", SVG_X(s->x[i]), SVG_Y(s->y[i]));
            }
            if (open) fprintf(f, "\"/>\n");
        }
        /* legend */
        {
            const double ly = T + 10 + 18 * k, lx = L + pw + 12;
            if (s->style == SVG_DOTS)
                fprintf(f, "<circle cx=\"%g\" cy=\"%g\" r=\"3\" fill=\"%s\"/>\n", lx + 10, ly, col);
            else
                fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"%s\" stroke-width=\"2\"%s/>\n",
                        lx, ly, lx + 20, ly, col, s->style == SVG_DASHED ? " stroke-dasharray=\"5,3\"" : "");
            fprintf(f, "<text x=\"%g\" y=\"%g\">", lx + 26, ly + 4);
            svg_escape(f, s->label);
            fprintf(f, "</text>\n");
        }
    }
#undef SVG_X
#undef SVG_Y
#undef SVG_PX
#undef SVG_PY
#undef SVG_TX
#undef SVG_TY
    fprintf(f, "</svg>\n");
    return fclose(f) == 0 ? 0 : -1;
}

#endif
