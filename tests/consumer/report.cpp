// tests/consumer/report.cpp - the declarations of sph.h used from C++ (no SPH_IMPLEMENTATION).
#include "sph.h"

#include <cstdio>

extern "C" void consumer_report(const sph_world* w);

void consumer_report(const sph_world* w) {
    std::printf("consumer: %zu fluid + %zu wall particles, %llu steps, t = %.3f s (from C++)\n",
                w->n, w->nb, static_cast<unsigned long long>(w->steps), w->time);
}
