/* tests/test_io.c - the ParaView writers: sph_write_vtu and sph_write_vtu_series.

   These tests parse our own .vtu (the XML header's offsets and the raw appended blocks) and
   compare every value bit for bit with the world; tests/check_vtk.py reads the same kind of
   files with VTK's own reader (make check-vtk), which is the independent check. */
#include "harness.h"
#include "../sph.h"

#include <stdlib.h>
#include <string.h>

/* The whole file in a malloc'ed buffer (NUL-terminated), its length in *len. */
static char* slurp(const char* path, size_t* len) {
    FILE* f = fopen(path, "rb");
    char* buf;
    long size;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return NULL;
    }
    buf = (char*)malloc((size_t)size + 1);
    if (buf && fread(buf, 1, (size_t)size, f) != (size_t)size) { free(buf); buf = NULL; }
    fclose(f);
    if (buf) { buf[size] = 0; *len = (size_t)size; }
    return buf;
}

/* Parsed .vtu: the start of the raw appended data and the header text. */
typedef struct vtu_file {
    char* buf;
    size_t len;
    const char* data; /* first byte after the '_' that starts the appended data */
} vtu_file;

static int vtu_open(vtu_file* v, const char* path) {
    const char* a;
    v->buf = slurp(path, &v->len);
    v->data = NULL;
    if (!v->buf) return 0;
    a = strstr(v->buf, "<AppendedData encoding=\"raw\">");
    if (!a) return 0;
    a = strchr(a, '_');
    if (!a) return 0;
    v->data = a + 1;
    return 1;
}

/* The declaration of array `name` (Name="..." attribute, or "Points" for the positions): its
   type and offset. Returns a pointer to the block's values and sets *bytes, or NULL. */
static const unsigned char* vtu_array(const vtu_file* v, const char* name, const char* type,
                                      uint64_t* bytes) {
    char key[128];
    const char *d, *o;
    unsigned long long off;
    uint64_t n;
    if (strcmp(name, "Points") == 0) {
        d = strstr(v->buf, "<Points>");
        if (!d) return NULL;
        d = strstr(d, "<DataArray");
    } else {
        snprintf(key, sizeof key, "Name=\"%s\"", name);
        d = strstr(v->buf, key);
        while (d && d > v->buf && strncmp(d, "<DataArray", 10) != 0) --d;
    }
    if (!d || d > v->data) return NULL;
    snprintf(key, sizeof key, "type=\"%s\"", type);
    o = strstr(d, key);
    if (!o || o > strchr(d, '>')) return NULL;
    o = strstr(d, "offset=\"");
    if (!o || sscanf(o + 8, "%llu", &off) != 1) return NULL;
    if ((size_t)(v->data - v->buf) + off + 8 > v->len) return NULL;
    memcpy(&n, v->data + off, 8);
    if ((size_t)(v->data - v->buf) + off + 8 + n > v->len) return NULL;
    *bytes = n;
    return (const unsigned char*)v->data + off + 8;
}

static int count_substr(const char* s, const char* sub) {
    int c = 0;
    for (s = strstr(s, sub); s; s = strstr(s + 1, sub)) ++c;
    return c;
}

static int small_dam(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    sph_real lo[2] = {0, 0}, hi[2] = {0.2, 0.3}, tank[2] = {0.6, 0.4};
    sph_phase water;
    int ph;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    def.spacing = 0.02;
    if (sph_world_init(w, &def) != SPH_OK) return -1;
    ph = sph_world_add_phase(w, &water);
    if (ph < 0 || sph_fill_box(w, ph, lo, hi) != SPH_OK ||
        sph_add_wall_box(w, lo, tank, 0, SPH_FACE_YMAX) != SPH_OK)
        return -1;
    return ph;
}

#define REAL_TYPE (sizeof(sph_real) == 4 ? "Float32" : "Float64")

/* Every point value of the .vtu is the world's, bit for bit; fluid first, then walls. */
static void check_vtu_matches(const sph_world* w, const char* path) {
    vtu_file v;
    uint64_t bytes = 0;
    const unsigned char* a;
    const size_t n = w->n + w->nb, d = (size_t)w->dim, rs = sizeof(sph_real);
    size_t i, bad = 0;
    int k;
    double t = -1;
    const char* tv;
    if (!vtu_open(&v, path)) {
        CHECK_MSG(0, "cannot parse %s", path);
        free(v.buf);
        return;
    }
    CHECK(strstr(v.buf, "type=\"UnstructuredGrid\"") != NULL);
    CHECK(count_substr(v.buf, "NumberOfPoints=") == 1);
    {
        unsigned long long np = 0, nc = 0;
        const char* pc = strstr(v.buf, "NumberOfPoints=\"");
        CHECK(pc && sscanf(pc, "NumberOfPoints=\"%llu\" NumberOfCells=\"%llu\"", &np, &nc) == 2);
        CHECK_EQ_INT(np, n);
        CHECK_EQ_INT(nc, n);
    }
    tv = strstr(v.buf, "Name=\"TimeValue\"");
    CHECK(tv != NULL);
    if (tv) {
        tv = strchr(tv, '>');
        CHECK(tv && sscanf(tv + 1, "%lf", &t) == 1);
    }
    CHECK(t == w->time); /* %.17g round trip */

    a = vtu_array(&v, "Points", REAL_TYPE, &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * 3 * rs);
        for (i = 0; i < n; ++i)
            for (k = 0; k < 3; ++k) {
                sph_real got, want = 0;
                memcpy(&got, a + (i * 3 + (size_t)k) * rs, rs);
                if ((size_t)k < d) want = i < w->n ? w->x[i * d + (size_t)k] : w->b_x[(i - w->n) * d + (size_t)k];
                bad += memcmp(&got, &want, rs) != 0;
            }
    }
    a = vtu_array(&v, "velocity", REAL_TYPE, &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * 3 * rs);
        for (i = 0; i < n; ++i)
            for (k = 0; k < 3; ++k) {
                sph_real got, want = 0;
                memcpy(&got, a + (i * 3 + (size_t)k) * rs, rs);
                if ((size_t)k < d) want = i < w->n ? w->v[i * d + (size_t)k] : w->b_v[(i - w->n) * d + (size_t)k];
                bad += memcmp(&got, &want, rs) != 0;
            }
    }
    a = vtu_array(&v, "pressure", REAL_TYPE, &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * rs);
        for (i = 0; i < n; ++i) {
            sph_real got, want = i < w->n ? w->p[i] : w->b_p[i - w->n];
            memcpy(&got, a + i * rs, rs);
            bad += memcmp(&got, &want, rs) != 0;
        }
    }
    a = vtu_array(&v, "density", REAL_TYPE, &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * rs);
        for (i = 0; i < w->n; ++i) {
            sph_real got;
            memcpy(&got, a + i * rs, rs);
            bad += memcmp(&got, &w->rho[i], rs) != 0;
        }
        for (i = w->n; i < n; ++i) { /* walls: rho_b / rho0 times phase 0's rest density */
            sph_real got;
            memcpy(&got, a + i * rs, rs);
            bad += got != w->b_rho[i - w->n] * w->phases[0].rest_density;
        }
    }
    a = vtu_array(&v, "id", "UInt32", &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * 4);
        for (i = 0; i < n; ++i) {
            uint32_t got, want = i < w->n ? w->id[i] : w->b_id[i - w->n];
            memcpy(&got, a + i * 4, 4);
            bad += got != want;
        }
    }
    a = vtu_array(&v, "phase", "Int32", &bytes);
    CHECK(a != NULL);
    if (a) {
        for (i = 0; i < n; ++i) {
            int32_t got, want = i < w->n ? (int32_t)w->phase[i] : -1;
            memcpy(&got, a + i * 4, 4);
            bad += got != want;
        }
    }
    a = vtu_array(&v, "body", "Int32", &bytes);
    CHECK(a != NULL);
    if (a) {
        for (i = 0; i < n; ++i) {
            int32_t got, want = i < w->n ? -1 : (int32_t)w->b_body[i - w->n];
            memcpy(&got, a + i * 4, 4);
            bad += got != want;
        }
    }
    a = vtu_array(&v, "kind", "UInt8", &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n);
        for (i = 0; i < n; ++i) bad += a[i] != (i < w->n ? 0 : 1);
    }
    /* one vertex cell per point: connectivity i, offsets i + 1, type 1 (VTK_VERTEX) */
    a = vtu_array(&v, "connectivity", "Int32", &bytes);
    CHECK(a != NULL);
    if (a) {
        CHECK_EQ_INT(bytes, n * 4);
        for (i = 0; i < n; ++i) {
            int32_t c;
            memcpy(&c, a + i * 4, 4);
            bad += c != (int32_t)i;
        }
    }
    a = vtu_array(&v, "offsets", "Int32", &bytes);
    CHECK(a != NULL);
    if (a) {
        int32_t last;
        memcpy(&last, a + (n - 1) * 4, 4);
        CHECK_EQ_INT(last, n);
    }
    a = vtu_array(&v, "types", "UInt8", &bytes);
    CHECK(a != NULL);
    if (a) for (i = 0; i < n; ++i) bad += a[i] != 1;
    CHECK_EQ_INT(w->e != NULL, strstr(v.buf, "Name=\"internal_energy\"") != NULL);
    if (w->e) {
        a = vtu_array(&v, "internal_energy", REAL_TYPE, &bytes);
        CHECK(a != NULL);
        if (a)
            for (i = 0; i < w->n; ++i) {
                sph_real got;
                memcpy(&got, a + i * rs, rs);
                bad += memcmp(&got, &w->e[i], rs) != 0;
            }
    }
    CHECK_MSG(bad == 0, "%zu values differ from the world in %s", bad, path);
    /* the file ends after the appended data with the closing tags */
    CHECK(v.len > 30 && strcmp(v.buf + v.len - 30, "\n  </AppendedData>\n</VTKFile>\n") == 0);
    free(v.buf);
}

/* A 2D dam break with walls, written after some steps: all values exact. */
static void test_vtu_values(void) {
    sph_world w;
    int s;
    CHECK(small_dam(&w) >= 0);
    for (s = 0; s < 20; ++s) CHECK_EQ_INT(sph_step(&w, 1e-4), SPH_OK);
    CHECK_EQ_INT(sph_write_vtu(&w, "build/test_io_dam.vtu"), SPH_OK);
    check_vtu_matches(&w, "build/test_io_dam.vtu");
    TH_NOTE("%zu fluid + %zu wall particles", w.n, w.nb);
    sph_world_free(&w);
}

/* A 3D world with a gas phase (internal energy) and a 1D one. */
static void test_vtu_3d_gas_and_1d(void) {
    sph_world w;
    sph_world_def def = sph_world_def_default(3);
    sph_phase gas;
    sph_real lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
    int ph, k;
    memset(&gas, 0, sizeof gas);
    gas.rest_density = 1;
    gas.eos = SPH_EOS_IDEAL_GAS;
    gas.back_pressure = 1e5;
    def.spacing = 0.02;
    def.gravity[1] = 0;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    ph = sph_world_add_phase(&w, &gas);
    CHECK(ph >= 0);
    CHECK_EQ_INT(sph_fill_box(&w, ph, lo, hi), SPH_OK);
    CHECK(w.e != NULL);
    for (k = 0; k < (int)w.n; ++k) w.e[k] *= (sph_real)(1 + 0.01 * k); /* distinct values */
    CHECK_EQ_INT(sph_write_vtu(&w, "build/test_io_gas3d.vtu"), SPH_OK);
    check_vtu_matches(&w, "build/test_io_gas3d.vtu");
    sph_world_free(&w);

    def = sph_world_def_default(1);
    def.spacing = 0.1;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    memset(&gas, 0, sizeof gas);
    gas.rest_density = 1000;
    lo[0] = 0;
    hi[0] = 1;
    ph = sph_world_add_phase(&w, &gas);
    CHECK_EQ_INT(sph_fill_box(&w, ph, lo, hi), SPH_OK);
    CHECK_EQ_INT(sph_write_vtu(&w, "build/test_io_1d.vtu"), SPH_OK);
    check_vtu_matches(&w, "build/test_io_1d.vtu");
    sph_world_free(&w);
}

/* A series: one .vtu per frame, the .pvd complete after every frame, frames in time order,
   file names relative to the .pvd; a foreign .pvd is refused and left alone. */
static void test_vtu_series(void) {
    sph_world w;
    char* pvd;
    size_t len = 0;
    int frame, s;
    double last_t = -1;
    CHECK(small_dam(&w) >= 0);
    for (frame = 0; frame < 3; ++frame) {
        const char* p;
        char vtu[64];
        int entries = 0;
        CHECK_EQ_INT(sph_write_vtu_series(&w, "build/test_io_series", frame), SPH_OK);
        snprintf(vtu, sizeof vtu, "build/test_io_series_%04d.vtu", frame);
        check_vtu_matches(&w, vtu);
        pvd = slurp("build/test_io_series.pvd", &len);
        CHECK(pvd != NULL);
        if (!pvd) break;
        CHECK(strncmp(pvd, "<?xml", 5) == 0);
        CHECK(len > 27 && strcmp(pvd + len - 27, "  </Collection>\n</VTKFile>\n") == 0);
        for (p = strstr(pvd, "<DataSet"); p; p = strstr(p + 1, "<DataSet")) {
            double t = -1;
            int fr = -1;
            CHECK(sscanf(p, "<DataSet timestep=\"%lf\" part=\"0\" file=\"test_io_series_%d.vtu\"", &t,
                         &fr) == 2);
            CHECK_EQ_INT(fr, entries);
            if (entries == frame) {
                CHECK(t == w.time);
                CHECK(t > last_t);
                last_t = t;
            }
            ++entries;
        }
        CHECK_EQ_INT(entries, frame + 1);
        free(pvd);
        for (s = 0; s < 10; ++s) CHECK_EQ_INT(sph_step(&w, 1e-4), SPH_OK);
    }
    sph_world_free(&w);
}

static void test_io_errors(void) {
    sph_world w;
    FILE* f;
    char* text;
    size_t len = 0;
    const char* foreign = "<?xml version=\"1.0\"?>\n<something>else</something>\n";
    CHECK(small_dam(&w) >= 0);
    CHECK_EQ_INT(sph_write_vtu(NULL, "build/x.vtu"), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_write_vtu(&w, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_write_vtu(&w, "build/no/such/dir/x.vtu"), SPH_ERR_IO);
    CHECK_EQ_INT(sph_write_vtu_series(&w, "build/test_io_err", -1), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_write_vtu_series(&w, "build/no/such/dir/s", 0), SPH_ERR_IO);
    /* a later frame without the .pvd of frame 0 */
    remove("build/test_io_missing.pvd");
    remove("build/test_io_missing_0001.vtu");
    CHECK_EQ_INT(sph_write_vtu_series(&w, "build/test_io_missing", 1), SPH_ERR_IO);
    f = fopen("build/test_io_missing_0001.vtu", "rb"); /* a refused call writes nothing */
    CHECK(f == NULL);
    if (f) fclose(f);
    /* a .pvd that this library did not write is refused and left as it was */
    remove("build/test_io_foreign_0001.vtu");
    f = fopen("build/test_io_foreign.pvd", "wb");
    CHECK(f != NULL);
    if (f) { fputs(foreign, f); fclose(f); }
    CHECK_EQ_INT(sph_write_vtu_series(&w, "build/test_io_foreign", 1), SPH_ERR_IO);
    text = slurp("build/test_io_foreign.pvd", &len);
    CHECK(text && strcmp(text, foreign) == 0);
    free(text);
    f = fopen("build/test_io_foreign_0001.vtu", "rb");
    CHECK(f == NULL);
    if (f) fclose(f);
    CHECK_EQ_INT(sph_status_string(SPH_ERR_IO)[0] != 0, 1);
    sph_world_free(&w);
}

const th_test tests_io[] = {
    {"io/vtu_values_exact", test_vtu_values},
    {"io/vtu_3d_gas_1d", test_vtu_3d_gas_and_1d},
    {"io/vtu_series_pvd", test_vtu_series},
    {"io/errors", test_io_errors},
    {0, 0},
};
