#pragma once
// `octray view --bench`: what the viewer sustains, measured without a browser — the time to
// the first picture, and how many pictures a second it delivers while the camera orbits
// (each rendered as a moving camera is, then tone-mapped and encoded as the picture stream
// sends it to the page: a preview as JPEG).

#include "view/view_session.h"

namespace octray::view {

struct ViewBenchResult {
    double first_picture_seconds = 0.0;  // session start to its first published picture
    int first_width = 0, first_height = 0, first_spp = 0;
    int updates = 0;  // orbit steps rendered
    int update_width = 0, update_height = 0;
    double seconds = 0.0;  // wall-clock time of all updates
    double updates_per_second = 0.0;
    double mrays_per_second = 0.0;  // rays of all updates / their render time
    double sent_bytes = 0.0;        // mean size of an update as the page is sent it
    // The last update's picture encoded each way the page could be sent it (the mean of
    // 10 runs, one thread, milliseconds): tone mapping to 8-bit sRGB (every
    // way needs it), then PNG (zlib level 1), JPEG at kStreamJpegQuality, or raw RGBA8 (a
    // copy with an alpha byte: what an ImageData takes).
    double tone_map_ms = 0.0, png_ms = 0.0, jpeg_ms = 0.0, rgba_ms = 0.0;
    double last_png_bytes = 0.0, jpeg_bytes = 0.0, rgba_bytes = 0.0;
};

// Starts a session of `scene` with `settings`, waits for its first picture, then moves the
// camera `updates` times around its look-at point (one full turn about the up axis, as a
// drag does), each as a moving camera, waiting for each picture and encoding it as the
// picture stream does (encode_for_page).
// `updates` >= 1. Throws what the session throws.
ViewBenchResult bench_orbit(const Scene& scene, const ViewSettings& settings, int updates);

}  // namespace octray::view
