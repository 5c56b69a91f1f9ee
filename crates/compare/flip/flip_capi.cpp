// C ABI over NVIDIA's FLIP.h (the reference implementation, vendored unchanged beside this file)
// for crates/compare/src/flip.rs. It does what flip-evaluator's Python `evaluate` does (its
// nanobindFLIP.cpp), so our numbers are the reference's: optional sRGB decoding with FLIP's own
// function, then the fourth FLIP::evaluate overload, whose mean is the reference's float sum.
// No C++ exception or exit() may cross into Rust: every entry point catches, and the Rust side
// validates what FLIP.h would otherwise exit() on (start exposure > stop exposure).

#include "FLIP.h"

#include <cstring>
#include <string>
#include <vector>

namespace {
const char* tonemapper_name(int t) {
    switch (t) {
    case 0: return "reinhard";
    case 2: return "hable";
    default: return "aces";
    }
}
}

extern "C" {

// Exposure range HDR-FLIP derives from the reference (linear RGB, 3 floats a pixel) when the
// user gives none. Returns 0, or 1 on a C++ exception (allocation failure).
int spectra_flip_exposures(const float* reference, int width, int height, int tonemapper, float* start, float* stop) {
    try {
        FLIP::image<FLIP::color3> img(width, height);
        img.setPixels(reference, width, height);
        img.computeExposures(tonemapper_name(tonemapper), *start, *stop);
        return 0;
    } catch (...) {
        return 1;
    }
}

// FLIP of `test` against `reference` (3 floats a pixel, row-major; sRGB-encoded when
// srgb_input, else linear). For HDR, start/stop exposures must be finite with start <= stop and
// num_exposures >= 2 or -1 (FLIP's default, ceil(stop - start) but at least 2); the count used
// is returned in *num_exposures_used. Writes width*height errors to map_out and their mean to
// *mean_out. Returns 0, or 1 on a C++ exception.
int spectra_flip_evaluate(const float* reference, const float* test, int width, int height, int use_hdr,
                          int srgb_input, float ppd, float start_exposure, float stop_exposure, int num_exposures,
                          int tonemapper, float* map_out, float* mean_out, int* num_exposures_used) {
    try {
        const size_t n = size_t(width) * size_t(height) * 3;
        std::vector<float> r(reference, reference + n), t(test, test + n);
        if (srgb_input) {
            for (size_t i = 0; i < n; i++) {
                r[i] = FLIP::color3::sRGBToLinearRGB(r[i]);
                t[i] = FLIP::color3::sRGBToLinearRGB(t[i]);
            }
        }
        FLIP::Parameters p;
        p.PPD = ppd;
        if (use_hdr) {
            p.startExposure = start_exposure;
            p.stopExposure = stop_exposure;
            p.numExposures = num_exposures;
            p.tonemapper = tonemapper_name(tonemapper);
        }
        float mean = -1.0f;
        float* map = nullptr;
        FLIP::evaluate(r.data(), t.data(), width, height, use_hdr != 0, p, false, true, mean, &map);
        std::memcpy(map_out, map, size_t(width) * size_t(height) * sizeof(float));
        delete[] map;
        *mean_out = mean;
        *num_exposures_used = p.numExposures;
        return 0;
    } catch (...) {
        return 1;
    }
}

// FLIP's magma colour of each error (the lookup its tool uses for error-map PNGs), 3 floats each.
void spectra_flip_magma(const float* values, int count, float* rgb_out) {
    for (int i = 0; i < count; i++) {
        const FLIP::color3 c = FLIP::MapMagma[int(values[i] * 255.0f + 0.5f) % 256];
        rgb_out[3 * i] = c.r;
        rgb_out[3 * i + 1] = c.g;
        rgb_out[3 * i + 2] = c.b;
    }
}
}
