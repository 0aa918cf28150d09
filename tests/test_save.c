/* tests/test_save.c - save / restore / copy: a run that saves, restores and continues is bitwise
   identical to one that did not, for every solver; damaged and foreign files are refused with a
   reason; a blow-up can be retried from a checkpoint. */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"
#include "state_hash.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* FNV-1a over the state a user sees: fluid x, v, rho, p, id, (e), boundary x, v, p, time. */
#define world_hash th_state_hash

typedef sph_status (*scene_fn)(sph_world* w);

static sph_real fixed_dt; /* > 0: every step takes it; else sph_stable_dt */

static sph_status steps(sph_world* w, int count) {
    int k;
    for (k = 0; k < count; ++k) {
        sph_real dt = fixed_dt > 0 ? fixed_dt : sph_stable_dt(w, w->def.solver);
        sph_status s = th_step(w, dt);
        if (s != SPH_OK) return s;
    }
    return SPH_OK;
}

static sph_status dam(sph_world* w, sph_world_def def) {
    sph_real lo[2] = {0, 0}, col[2] = {0.2, 0.4}, tank[2] = {0.6, 0.5};
    sph_phase water;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    def.spacing = 0.02;
    if (sph_world_init(w, &def) != SPH_OK) return w->status;
    if (sph_world_add_phase(w, &water) < 0) return w->status;
    if (sph_fill_box(w, 0, lo, col) != SPH_OK) return w->status;
    return sph_add_wall_box(w, lo, tank, 0, 0);
}

static sph_status s_wcsph(sph_world* w) { return dam(w, sph_world_def_default(2)); }
static sph_status s_wcsph_verlet(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    def.integrator = SPH_INTEGRATOR_VERLET;
    def.boundary_volume = SPH_BVOL_AKINCI;
    return dam(w, def);
}
static sph_status s_pcisph(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    sph_world_def_pcisph(&def, 1);
    return dam(w, def);
}
/* at its own steps (max_dt 2 ms before): the step does not enter the bit-exactness check */
static sph_status s_pcisph_orig(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    sph_world_def_pcisph(&def, 0);
    return dam(w, def);
}
static sph_status s_iisph(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    def.solver = SPH_SOLVER_IISPH;
    return dam(w, def);
}
/* two phases of different density in a closed 3D box: particle density, per-phase walls */
static sph_status s_multiphase3d(sph_world* w) {
    sph_world_def def = sph_world_def_default(3);
    sph_real lo[3] = {0, 0, 0}, mid[3] = {0.16, 0.08, 0.12}, lo2[3] = {0, 0.08, 0},
             hi[3] = {0.16, 0.16, 0.12}, box[3] = {0.16, 0.2, 0.12};
    sph_phase a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.rest_density = 1000;
    b.rest_density = 500;
    def.spacing = 0.02;
    def.density = SPH_DENSITY_PARTICLE;
    def.pressure_grad = SPH_PGRAD_MULTIPHASE;
    if (sph_world_init(w, &def) != SPH_OK) return w->status;
    if (sph_world_add_phase(w, &a) < 0 || sph_world_add_phase(w, &b) < 0) return w->status;
    if (sph_fill_box(w, 0, lo, mid) != SPH_OK || sph_fill_box(w, 1, lo2, hi) != SPH_OK)
        return w->status;
    if (sph_add_wall_box(w, lo, box, 0, 0) != SPH_OK) return w->status;
    return sph_set_hydrostatic(w);
}
/* 1D gas with a density jump carried by masses (per-particle mass array, internal energy) */
static sph_status s_compressible(sph_world* w) {
    sph_world_def def = sph_world_def_default(1);
    sph_phase gas;
    sph_real x[200], m[200], rho[200];
    int i;
    def.spacing = (sph_real)0.01;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = SPH_DENSITY_PARTICLE;
    def.pressure_grad = SPH_PGRAD_MULTIPHASE;
    def.periodic[0] = 1;
    def.domain_lo[0] = 0;
    def.domain_hi[0] = 2;
    memset(&gas, 0, sizeof gas);
    gas.rest_density = 1;
    gas.eos = SPH_EOS_IDEAL_GAS;
    gas.back_pressure = 1;
    if (sph_world_init(w, &def) != SPH_OK) return w->status;
    if (sph_world_add_phase(w, &gas) < 0) return w->status;
    for (i = 0; i < 200; ++i) {
        x[i] = (sph_real)(0.01 * (i + 0.5));
        rho[i] = (sph_real)(x[i] < 1 ? 1 : 0.125);
        m[i] = (sph_real)0.01 * rho[i];
    }
    return sph_add_fluid_ex(w, 0, 200, x, NULL, m, rho);
}
/* the second-order scheme: its neighbour lists are kept over several steps */
static sph_status s_second_order(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    def.kernel = SPH_KERNEL_QUINTIC;
    def.h_factor = (sph_real)1.2;
    def.cfl = (sph_real)0.3;
    def.scheme = SPH_SCHEME_SECOND_ORDER;
    def.alpha = 0;
    def.delta = 0;
    def.shift_every = 3;
    return scene_taylor_green(w, def, 16, 10);
}
/* moving boundaries: the callback is passed to the loader again */
static scene_stirrer stirrer;
static sph_status s_stirrer(sph_world* w) {
    sph_world_def def = sph_world_def_default(2);
    def.solver = SPH_SOLVER_IISPH;
    stirrer.omega = 3.14159265358979323846;
    return scene_stirrer_build(w, def, 0.04, 0.6, &stirrer);
}

/* Runs 2K steps straight; then K steps, save (file and memory copy), K more; the restored
   worlds continue K steps: all three end bitwise equal. */
static void check_restart(const char* name, scene_fn scene, int K, sph_real dt) {
    sph_world a, b, c;
    uint64_t ha, hb, hc;
    sph_world_def cb;
    char path[128];
    fixed_dt = dt;
    snprintf(path, sizeof path, "build/test_save_%s.sphw", name);
    CHECK_EQ_INT(scene(&a), SPH_OK);
    CHECK_MSG(steps(&a, K) == SPH_OK, "%s: %s", name, a.error);
    CHECK_EQ_INT(sph_world_save(&a, path), SPH_OK);
    CHECK_EQ_INT(sph_world_copy(&c, &a), SPH_OK);
    CHECK_EQ_INT(c.n, a.n);
    CHECK_EQ_INT(steps(&a, K), SPH_OK);
    ha = world_hash(&a);
    cb = a.def; /* the callbacks of the original def */
    CHECK_EQ_INT(sph_world_load(&b, path, &cb), SPH_OK);
    CHECK_EQ_INT(b.n, a.n);
    CHECK_EQ_INT(b.nb, a.nb);
    CHECK_EQ_INT(steps(&b, K), SPH_OK);
    CHECK_EQ_INT(steps(&c, K), SPH_OK);
    hb = world_hash(&b);
    hc = world_hash(&c);
    CHECK_MSG(ha == hb, "%s: restored from file and continued differs from the straight run", name);
    CHECK_MSG(ha == hc, "%s: the copy continued differs from the straight run", name);
    CHECK_EQ_INT(b.steps, a.steps);
    TH_NOTE("%-14s %zu fluid + %zu boundary particles, %d + %d steps: restart bitwise identical "
            "(%s)", name, a.n, a.nb, K, K, ha == hb && ha == hc ? "yes" : "NO");
    sph_world_free(&a);
    sph_world_free(&b);
    sph_world_free(&c);
    fixed_dt = 0;
}

static void test_restart_wcsph(void) {
    check_restart("wcsph", s_wcsph, 40, 0);
    check_restart("wcsph_verlet", s_wcsph_verlet, 40, 0);
    check_restart("multiphase3d", s_multiphase3d, 20, 0);
}
static void test_restart_pcisph(void) {
    check_restart("pcisph", s_pcisph, 15, 0);
    check_restart("pcisph_orig", s_pcisph_orig, 15, 0);
}
static void test_restart_iisph(void) {
    check_restart("iisph", s_iisph, 15, 0);
    check_restart("stirrer", s_stirrer, 15, (sph_real)0.004);
}
static void test_restart_compressible(void) { check_restart("compressible", s_compressible, 30, 0); }
static void test_restart_second_order(void) {
    sph_world w;
    check_restart("second_order", s_second_order, 12, 0);
    /* the lists are really kept across steps there (else the test above proves less) */
    CHECK_EQ_INT(s_second_order(&w), SPH_OK);
    CHECK_EQ_INT(steps(&w, 3), SPH_OK);
    CHECK(w.priv.snl_valid);
    sph_world_free(&w);
}

/* Bytes of a file. */
static unsigned char* read_all(const char* path, size_t* n) {
    FILE* f = fopen(path, "rb");
    unsigned char* b;
    long s;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    s = ftell(f);
    fseek(f, 0, SEEK_SET);
    b = (unsigned char*)malloc((size_t)s + 1);
    if (b && fread(b, 1, (size_t)s, f) != (size_t)s) { free(b); b = NULL; }
    fclose(f);
    *n = (size_t)s;
    return b;
}

static sph_status load_bytes(sph_world* w, const unsigned char* b, size_t n) {
    return sph_world_load_mem(w, b, n, NULL);
}

/* Damaged, truncated, foreign and other-build files: SPH_ERR_IO with the reason; the world is
   left empty and safe to free. */
static void test_bad_files(void) {
    sph_world a, b;
    unsigned char* bytes;
    unsigned char* copy;
    size_t n = 0, cut, size;
    int cases = 0;
    uint32_t v;
    CHECK_EQ_INT(s_wcsph(&a), SPH_OK);
    CHECK_EQ_INT(steps(&a, 5), SPH_OK);
    CHECK_EQ_INT(sph_world_save(&a, "build/test_save_bad.sphw"), SPH_OK);
    bytes = read_all("build/test_save_bad.sphw", &n);
    CHECK(bytes != NULL);
    if (!bytes) return;
    size = sph_world_save_mem(&a, NULL, 0);
    CHECK_EQ_INT(size, n);
    copy = (unsigned char*)malloc(n);
    /* memory save equals the file */
    CHECK_EQ_INT(sph_world_save_mem(&a, copy, n), n);
    CHECK(memcmp(copy, bytes, n) == 0);
    /* too small a buffer: nothing written, the size returned */
    memset(copy, 0xAB, n);
    CHECK_EQ_INT(sph_world_save_mem(&a, copy, n - 1), n);
    CHECK(copy[0] == 0xAB);

    /* truncated at many lengths */
    for (cut = 0; cut < n; cut += n / 37 + 1) {
        CHECK_EQ_INT(load_bytes(&b, bytes, cut), SPH_ERR_IO);
        CHECK(b.n == 0 && b.x == NULL && b.error[0] != 0);
        sph_world_free(&b);
        ++cases;
    }
    /* one flipped bit anywhere: the checksum (or the header check) refuses it */
    for (cut = 0; cut < n; cut += n / 53 + 1) {
        memcpy(copy, bytes, n);
        copy[cut] ^= 0x10;
        CHECK_EQ_INT(load_bytes(&b, copy, n), SPH_ERR_IO);
        sph_world_free(&b);
        ++cases;
    }
    memcpy(copy, bytes, n);
    copy[n / 2] ^= 1;
    CHECK_EQ_INT(load_bytes(&b, copy, n), SPH_ERR_IO);
    CHECK_MSG(strstr(b.error, "checksum") != NULL, "message: %s", b.error);
    sph_world_free(&b);
    /* foreign bytes */
    CHECK_EQ_INT(load_bytes(&b, (const unsigned char*)"<?xml version=\"1.0\"?>", 21), SPH_ERR_IO);
    CHECK_MSG(strstr(b.error, "not an sph.h world file") != NULL, "message: %s", b.error);
    sph_world_free(&b);
    /* a newer format version, the other precision, a different build */
    memcpy(copy, bytes, n);
    v = 99;
    memcpy(copy + 8, &v, 4);
    CHECK_EQ_INT(load_bytes(&b, copy, n), SPH_ERR_IO);
    CHECK_MSG(strstr(b.error, "format version 99") != NULL, "message: %s", b.error);
    sph_world_free(&b);
    memcpy(copy, bytes, n);
    v = sizeof(sph_real) == 8 ? 4 : 8;
    memcpy(copy + 16, &v, 4);
    CHECK_EQ_INT(load_bytes(&b, copy, n), SPH_ERR_IO);
    CHECK_MSG(strstr(b.error, "-byte reals") != NULL, "message: %s", b.error);
    sph_world_free(&b);
    memcpy(copy, bytes, n);
    v = 1;
    memcpy(copy + 20, &v, 4);
    CHECK_EQ_INT(load_bytes(&b, copy, n), SPH_ERR_IO);
    CHECK_MSG(strstr(b.error, "different build") != NULL, "message: %s", b.error);
    sph_world_free(&b);
    cases += 6;
    CHECK_EQ_INT(sph_world_load(&b, "build/no/such/file.sphw", NULL), SPH_ERR_IO);
    CHECK(strstr(b.error, "cannot open") != NULL);
    sph_world_free(&b);
    CHECK_EQ_INT(sph_world_save(&a, "build/no/such/dir/x.sphw"), SPH_ERR_IO);
    /* and the intact bytes load */
    CHECK_EQ_INT(load_bytes(&b, bytes, n), SPH_OK);
    CHECK(world_hash(&b) == world_hash(&a));
    sph_world_free(&b);
    TH_NOTE("%d damaged or foreign inputs refused; a %zu-byte file for %zu + %zu particles", cases,
            n, a.n, a.nb);
    free(bytes);
    free(copy);
    sph_world_free(&a);
}

/* A blow-up is retried from a checkpoint: too large a time step fails (reported), the world is
   restored from the copy taken before, and the retry with the stable step ends exactly where a
   run that never failed ends. */
static void test_blowup_retry(void) {
    sph_world w, checkpoint, reference;
    sph_status s = SPH_OK;
    int k, failed_at = -1;
    CHECK_EQ_INT(s_wcsph(&w), SPH_OK);
    CHECK_EQ_INT(steps(&w, 10), SPH_OK);
    CHECK_EQ_INT(sph_world_copy(&checkpoint, &w), SPH_OK);
    CHECK_EQ_INT(sph_world_copy(&reference, &w), SPH_OK);
    for (k = 0; k < 400 && s == SPH_OK; ++k) {
        s = th_step(&w, 12 * sph_stable_dt(&w, w.def.solver));
        if (s != SPH_OK) failed_at = k;
    }
    CHECK_EQ_INT(s, SPH_ERR_UNSTABLE);
    sph_world_free(&w);
    CHECK_EQ_INT(sph_world_copy(&w, &checkpoint), SPH_OK);
    CHECK_EQ_INT(steps(&w, 30), SPH_OK);
    CHECK_EQ_INT(steps(&reference, 30), SPH_OK);
    CHECK(world_hash(&w) == world_hash(&reference));
    TH_NOTE("12x the stable dt: SPH_ERR_UNSTABLE at step %d; restored from the checkpoint, 30 stable "
            "steps match an uninterrupted run bit for bit", failed_at + 1);
    sph_world_free(&w);
    sph_world_free(&checkpoint);
    sph_world_free(&reference);
}

const th_test tests_save[] = {
    {"save/restart_wcsph", test_restart_wcsph},
    {"save/restart_pcisph", test_restart_pcisph},
    {"save/restart_iisph", test_restart_iisph},
    {"save/restart_compressible", test_restart_compressible},
    {"save/restart_second_order", test_restart_second_order},
    {"save/bad_files", test_bad_files},
    {"save/blowup_retry_from_checkpoint", test_blowup_retry},
    {0, 0},
};
