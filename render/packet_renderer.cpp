// The packet renderer: per tile, camera samples -> primary rays -> (closest hit -> shade ->
// shadow any-hit -> accumulate) per generation until no ray is left. Everything numeric
// happens in the kernels; this file owns memory, order and threads.

#include "render/packet_renderer.h"

#include <emmintrin.h>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "core/populate.h"
#include "core/random.h"
#include "kernels/dispatch.h"
#include "render/crop.h"
#include "render/parallel.h"
#include "render/prepare/bvh_build.h"
#include "render/prepare/scene_view.h"
#include "render/stream_row.h"
#include "render/tile_layout.h"
#include "scene/camera.h"

namespace octray {
namespace {

using kernels::kPacketWidth;

// The stream layout render/tile_layout.h states (and render/batch/memory_estimate.cpp counts).
static_assert(kTileStreamPacket == kPacketWidth);

// Rounds a stream length up to whole packets, with one spare packet.
std::size_t stream_capacity(std::size_t n) {
    return (n + kPacketWidth - 1) / kPacketWidth * kPacketWidth + kPacketWidth;
}

// Grows (never shrinks) a set of SoA columns: steady state allocates nothing. `kColumns`
// is the stream's column count in render/tile_layout.h, checked against the columns given.
template <std::size_t kColumns, class... Columns>
void grow(std::size_t n, Columns&... columns) {
    static_assert(sizeof...(Columns) == kColumns, "render/tile_layout.h: column count");
    static_assert(((sizeof(typename Columns::value_type) == kTileColumnBytes) && ...),
                  "render/tile_layout.h: column element size");
    const std::size_t capacity = stream_capacity(n);
    // reserve first: resize alone may allocate up to twice the size (libstdc++ grows
    // geometrically), and render/batch/memory_estimate.cpp counts exactly `capacity` elements.
    ((columns.size() < capacity ? (columns.reserve(capacity), columns.resize(capacity))
                                : void()),
     ...);
}

struct SampleStorage {
    AlignedVector<float> x, y, lens_u, lens_v;
    AlignedVector<std::uint32_t> pixel;
    void reserve(std::size_t n) { grow<kSampleColumns>(n, x, y, lens_u, lens_v, pixel); }
    kernels::CameraSamples view() const {
        return {x.data(), y.data(), lens_u.data(), lens_v.data(), pixel.data()};
    }
};

struct RayStorage {
    AlignedVector<float> ox, oy, oz, dx, dy, dz, wr, wg, wb;
    AlignedVector<std::uint32_t> pixel;
    void reserve(std::size_t n) {
        grow<kRayColumns>(n, ox, oy, oz, dx, dy, dz, wr, wg, wb, pixel);
    }
    kernels::RayStream view() {
        return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(),
                dz.data(), wr.data(), wg.data(), wb.data(), pixel.data()};
    }
};

struct HitStorage {
    AlignedVector<float> t;
    AlignedVector<std::int32_t> object;
    void reserve(std::size_t n) { grow<kHitColumns>(n, t, object); }
    kernels::HitStream view() { return {t.data(), object.data()}; }
};

struct ShadowStorage {
    AlignedVector<float> ox, oy, oz, dx, dy, dz, t_max, term_r, term_g, term_b;
    AlignedVector<std::uint32_t> parent, occluded;
    void reserve(std::size_t n) {
        grow<kShadowColumns>(n, ox, oy, oz, dx, dy, dz, t_max, term_r, term_g, term_b, parent,
                             occluded);
    }
    kernels::ShadowStream view() {
        return {ox.data(),     oy.data(),     oz.data(),    dx.data(),
                dy.data(),     dz.data(),     t_max.data(), term_r.data(),
                term_g.data(), term_b.data(), parent.data()};
    }
};

struct ColorStorage {
    AlignedVector<float> local_r, local_g, local_b, refl_r, refl_g, refl_b, refr_r, refr_g,
        refr_b;
    void reserve(std::size_t n) {
        grow<kColorColumns>(n, local_r, local_g, local_b, refl_r, refl_g, refl_b, refr_r,
                            refr_g, refr_b);
    }
    kernels::SurfaceColor view() {
        return {local_r.data(), local_g.data(), local_b.data(), refl_r.data(), refl_g.data(),
                refl_b.data(),  refr_r.data(),  refr_g.data(),  refr_b.data()};
    }
};

// A tile traces each generation of its ray tree (primary rays, their mirror and refracted
// children, theirs, ...) in chunks of at most ray_chunk rays (kDefaultRayChunk), depth
// first. Breadth first, a tile whose every bounce spawns two rays above the weight cut-off
// would hold 2^depth rays per sample at its deepest generation; in chunks it holds at most
// a chunk per generation (and per camera-sample stream), whatever the depth and the samples
// per pixel. Chunking changes no pixel: every ray is traced and shaded alone, and a pixel
// adds its samples in order.

// Per secondary ray: where its color goes (kernels::ChildLinks).
struct LinkStorage {
    AlignedVector<std::uint32_t> parent;  // 2 * parent slot + (0 mirror, 1 refracted)
    AlignedVector<float> factor_r, factor_g, factor_b;
    void reserve(std::size_t n) { grow<kLinkColumns>(n, parent, factor_r, factor_g, factor_b); }
    kernels::ChildLinks view() {
        return {parent.data(), factor_r.data(), factor_g.data(), factor_b.data()};
    }
};

// One generation of a tile's ray tree, a chunk of its rays at a time: their colors, kept
// until their children's colors are known, and the children they spawn with their links.
struct Level {
    ColorStorage color;
    RayStorage next;
    LinkStorage next_links;
};

// A pixel of a tile, from its corner.
struct TilePixel {
    std::uint32_t x, y;
};
static_assert(sizeof(TilePixel) == kTilePixelOrderColumns * kTileColumnBytes);

// Per-thread scratch, reused tile after tile (and frame after frame: scratch_for_thread).
struct TileScratch {
    SampleStorage samples;
    RayStorage primary;
    HitStorage hits;                     // of the chunk being shaded, at any level
    ShadowStorage shadows;               // likewise
    std::vector<Level> levels;           // sized to max_depth + 1 before a tile, never shrinks
    std::vector<TilePixel> pixel_order;  // the tile's pixels in sample order
    int order_width = 0, order_height = 0;     // the tile shape pixel_order holds
    AlignedVector<float> acc_r, acc_g, acc_b;  // the tile's sums of samples:
                                               // kTileAccumulatorColumns

    // What the scratch holds now, in bytes (its high-water mark: it never shrinks).
    std::uint64_t bytes() const {
        std::uint64_t total = 0;
        const auto add = [&](const auto&... columns) {
            ((total += columns.capacity() * sizeof(columns[0])), ...);
        };
        add(samples.x, samples.y, samples.lens_u, samples.lens_v, samples.pixel);
        add(primary.ox, primary.oy, primary.oz, primary.dx, primary.dy, primary.dz, primary.wr,
            primary.wg, primary.wb, primary.pixel);
        add(hits.t, hits.object);
        add(shadows.ox, shadows.oy, shadows.oz, shadows.dx, shadows.dy, shadows.dz,
            shadows.t_max, shadows.term_r, shadows.term_g, shadows.term_b, shadows.parent,
            shadows.occluded);
        for (const Level& l : levels) {
            const ColorStorage& c = l.color;
            add(c.local_r, c.local_g, c.local_b, c.refl_r, c.refl_g, c.refl_b, c.refr_r,
                c.refr_g, c.refr_b);
            const RayStorage& r = l.next;
            add(r.ox, r.oy, r.oz, r.dx, r.dy, r.dz, r.wr, r.wg, r.wb, r.pixel);
            add(l.next_links.parent, l.next_links.factor_r, l.next_links.factor_g,
                l.next_links.factor_b);
        }
        add(pixel_order, acc_r, acc_g, acc_b);
        return total;
    }
};

// This thread's scratch. Kept for the life of the thread, so that a process's frames after
// the first (an animation, a benchmark, a progressive render's passes) touch no fresh
// memory: the first touch of a page is a page fault, and the buffers of a tile are
// rewritten every tile. A thread renders one tile at a time (render_tile calls no
// parallel code), so the scratch is never shared.
TileScratch& scratch_for_thread() {
    thread_local TileScratch scratch;
    return scratch;
}

// Maps the fresh pages of a render's frame before its tiles write them, on the render's
// threads (populate_pages_parallel): one madvise(MADV_POPULATE_WRITE) per 2 MiB instead of
// a page fault per 4 KiB page. The kernel still zeroes every page; a 1920x1080 frame (25
// MB) took 7-10 ms this way against 10-14 ms of faults (docs/performance-log.md,
// "Division-free rejection in the BVH leaves, render_tile's loops, the first frame").
void populate_frame(Image& image) {
    for (ImageChannel& channel : image.channels)
        populate_pages_parallel(channel.samples.data(), channel.samples.size());
}

// The rays of `rays` from `first` on: a chunk of a stream (first: a whole packet).
kernels::RayStream offset(const kernels::RayStream& r, std::uint32_t first) {
    return {r.ox + first, r.oy + first, r.oz + first, r.dx + first, r.dy + first,
            r.dz + first, r.wr + first, r.wg + first, r.wb + first, r.pixel + first};
}
kernels::ChildLinks offset(const kernels::ChildLinks& l, std::uint32_t first) {
    return {l.parent + first, l.factor_r + first, l.factor_g + first, l.factor_b + first};
}

// Each primary ray's color ((local + mirror tail) + refraction tail) onto its pixel's sum.
// At one sample per pixel, four rays in a row mostly fill four neighbouring pixels (a
// row of a 4 x 2 block): those take one 4-wide add per channel, the same sums as one by
// one (this loop, scalar, was 5 % of a random:1024 frame).
void accumulate_primary(const kernels::SurfaceColor& c, const std::uint32_t* pixel,
                        std::uint32_t count, TileScratch& s) {
    float* const acc[3] = {s.acc_r.data(), s.acc_g.data(), s.acc_b.data()};
    const float* const local[3] = {c.local_r, c.local_g, c.local_b};
    const float* const reflect[3] = {c.tail_reflect_r, c.tail_reflect_g, c.tail_reflect_b};
    const float* const refract[3] = {c.tail_refract_r, c.tail_refract_g, c.tail_refract_b};
    const auto add_one = [&](std::uint32_t q) {
        for (int k = 0; k < 3; ++k)
            acc[k][pixel[q]] += (local[k][q] + reflect[k][q]) + refract[k][q];
    };
    std::uint32_t r = 0;
    for (; r + 4 <= count; r += 4) {
        const std::uint32_t p = pixel[r];
        if (pixel[r + 1] == p + 1 && pixel[r + 2] == p + 2 && pixel[r + 3] == p + 3) {
            for (int k = 0; k < 3; ++k) {
                const __m128 color = _mm_add_ps(
                    _mm_add_ps(_mm_loadu_ps(local[k] + r), _mm_loadu_ps(reflect[k] + r)),
                    _mm_loadu_ps(refract[k] + r));
                _mm_storeu_ps(acc[k] + p, _mm_add_ps(_mm_loadu_ps(acc[k] + p), color));
            }
            continue;
        }
        for (std::uint32_t q = r; q < r + 4; ++q) add_one(q);
    }
    for (; r < count; ++r) add_one(r);
}

// Adds each unoccluded shadow ray's light term to its parent's color. Shadow rays of one
// parent come in light order, so the terms are summed in the reference's order.
void add_visible_terms(const ShadowStorage& shadows, std::uint32_t count,
                       const kernels::SurfaceColor& color) {
    const std::uint32_t* occluded = shadows.occluded.data();
    const std::uint32_t* parent = shadows.parent.data();
    const float *tr = shadows.term_r.data(), *tg = shadows.term_g.data(),
                *tb = shadows.term_b.data();
    for (std::uint32_t k = 0; k < count; ++k) {
        if (occluded[k] != 0) continue;
        const std::uint32_t p = parent[k];
        color.local_r[p] += tr[k];
        color.local_g[p] += tg[k];
        color.local_b[p] += tb[k];
    }
}

// A generation's colors ((local + mirror tail) + refraction tail) times their factor into
// their parents' tails: the reference's factor * trace(child).
void resolve_into_parents(const kernels::SurfaceColor& c, const kernels::ChildLinks& links,
                          std::uint32_t count, const kernels::SurfaceColor& up) {
    for (std::uint32_t r = 0; r < count; ++r) {
        const float cr = (c.local_r[r] + c.tail_reflect_r[r]) + c.tail_refract_r[r];
        const float cg = (c.local_g[r] + c.tail_reflect_g[r]) + c.tail_refract_g[r];
        const float cb = (c.local_b[r] + c.tail_reflect_b[r]) + c.tail_refract_b[r];
        // Mirror and refracted children are mixed in a stream: pick the tail by pointer,
        // not by a branch the CPU would mispredict.
        const std::uint32_t slot = links.parent[r] >> 1;
        const bool refracted = (links.parent[r] & 1u) != 0;
        (refracted ? up.tail_refract_r : up.tail_reflect_r)[slot] = links.factor_r[r] * cr;
        (refracted ? up.tail_refract_g : up.tail_reflect_g)[slot] = links.factor_g[r] * cg;
        (refracted ? up.tail_refract_b : up.tail_reflect_b)[slot] = links.factor_b[r] * cb;
    }
}

struct Tile {
    int x0, y0, width, height;  // in pixels of the full image
};

// A rectangle cut into tiles of options' size, row by row from its corner. A tile larger
// than the rectangle is the rectangle (and the tile counts cannot overflow).
struct TileGrid {
    PixelRect rect;
    int tw, th, tiles_x, tiles_y;

    TileGrid(const PixelRect& r, const RenderOptions& options)
        : rect(r),
          tw(std::clamp(options.tile_width, 1, r.width())),
          th(std::clamp(options.tile_height, 1, r.height())),
          tiles_x((r.width() + tw - 1) / tw),
          tiles_y((r.height() + th - 1) / th) {}

    int count() const { return tiles_x * tiles_y; }
    Tile at(int t) const {
        const int x0 = rect.x0 + (t % tiles_x) * tw, y0 = rect.y0 + (t / tiles_x) * th;
        return Tile{x0, y0, std::min(tw, rect.x1 - x0), std::min(th, rect.y1 - y0)};
    }
};

// Where a render's tiles go: the crop-sized image (and, for a progressive pass, the sums),
// and which samples of each pixel to trace (render/crop.h).
struct RenderTarget {
    Image& image;                       // R, G, B float32 planes (make_rgb_image)
    PixelRect rect;                     // the pixels `image` holds; tiles lie inside it
    SampleRange samples;                // [0, spp) for a plain render
    const Image* start_sums = nullptr;  // sums of samples [0, samples.begin) or nullptr
    Image* sums = nullptr;              // a progressive pass: where the new sums go
};

// Pixel blocks of 4 x 2 inside a tile: eight neighbouring pixels fill one packet at one
// sample per pixel.
constexpr int kBlockWidth = 4;
constexpr int kBlockHeight = 2;

class PacketTracer {
  public:
    PacketTracer(const CompiledScene& scene, const kernels::KernelTable& table,
                 std::uint32_t frame, const SphereBvh* bvh, std::uint32_t ray_chunk)
        : scene_(scene),
          view_(bvh ? make_scene_view(scene, *bvh) : make_scene_view(scene)),
          k_(table),
          frame_(frame),
          ray_chunk_(ray_chunk) {
        // One sample per pixel sits at the pixel center: the film position of a column
        // (row) is the same for every row (column), computed once.
        for (int i = 0; i < scene.width; ++i) center_x_.push_back(film_x(i, 0.5f, scene.width));
        for (int j = 0; j < scene.height; ++j)
            center_y_.push_back(film_y(j, 0.5f, scene.height));
    }

    // Traces the tile into `target`; false, leaving it unfinished, when `control` says to
    // stop: it is asked between chunks of camera samples and of each generation's rays, so
    // a tile of any spp and depth stops within a chunk's work (RenderOptions::cancel).
    bool render_tile(const Tile& tile, TileScratch& s, const RenderTarget& target,
                     RayCounts& counts, TileControl& control) const {
        const int first_sample = target.samples.begin, end_sample = target.samples.end;
        const auto per_pixel = static_cast<std::uint32_t>(end_sample - first_sample);
        const std::size_t pixels = static_cast<std::size_t>(tile.width) * tile.height;
        const std::size_t samples = pixels * per_pixel;
        s.acc_r.assign(pixels, 0.0f);
        s.acc_g.assign(pixels, 0.0f);
        s.acc_b.assign(pixels, 0.0f);
        // A progressive pass adds its samples onto the previous passes' sums, so each pixel
        // still sums its samples one after the other in sample order.
        const int ox = tile.x0 - target.rect.x0, oy = tile.y0 - target.rect.y0;
        if (target.start_sums != nullptr) {
            float* const acc[3] = {s.acc_r.data(), s.acc_g.data(), s.acc_b.data()};
            for (int c = 0; c < 3; ++c)
                for (int y = 0; y < tile.height; ++y)
                    std::copy_n(target.start_sums->plane(c) +
                                    static_cast<std::size_t>(oy + y) *
                                        static_cast<std::size_t>(target.rect.width()) +
                                    static_cast<std::size_t>(ox),
                                tile.width, acc[c] + static_cast<std::size_t>(y) * tile.width);
        }
        if (s.levels.size() < static_cast<std::size_t>(scene_.max_depth) + 1)
            s.levels.resize(static_cast<std::size_t>(scene_.max_depth) + 1);

        // The tile's pixels block by block (4 x 2 pixels each), row by row in a block; each
        // pixel's samples follow one another. Every stream below keeps this order per
        // pixel, so a pixel's contributions arrive in the same order whatever the tile size
        // and the chunking.
        // It depends on the tile's shape alone: built when the shape changes (most tiles of
        // a render have one shape; this loop was 2 % of a random:1024 frame).
        pixel_order_for(tile, s);

        // Camera samples, primary rays and their trees, a chunk of samples at a time.
        for (std::size_t first = 0; first < samples; first += ray_chunk_) {
            if (!control.proceed()) return false;
            const std::size_t n = std::min<std::size_t>(ray_chunk_, samples - first);
            camera_samples(tile, s, first, n, first_sample, per_pixel);
            s.primary.reserve(n);
            const std::uint32_t count = k_.camera_rays(
                view_, s.samples.view(), static_cast<std::uint32_t>(n), s.primary.view());
            counts.primary += count;
            if (count == 0) continue;
            trace_generation(0, s.primary.view(), count, s, counts, control);
            // Primary rays into their pixels, sample after sample.
            accumulate_primary(s.levels[0].color.view(), s.primary.pixel.data(), count, s);
        }

        if (!control.proceed()) return false;  // stopped inside the last chunk's trees
        // The mean of the samples so far: all spp of them, unless a progressive pass.
        const auto samples_so_far = static_cast<float>(end_sample);
        const float* const acc[3] = {s.acc_r.data(), s.acc_g.data(), s.acc_b.data()};
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < tile.height; ++y) {
                const float* sums = acc[c] + static_cast<std::size_t>(y) * tile.width;
                if (target.sums != nullptr)
                    std::copy_n(sums, tile.width, &target.sums->at(c, ox, oy + y));
                stream_row(&target.image.at(c, ox, oy + y), sums, tile.width, samples_so_far);
            }
        finish_streaming();
        return true;
    }

    // The closest hit of each pixel's sample-0 camera ray (the AOVs' hits: FirstHits in
    // render/render_result.h), into `out` at the tile's place; a ray the camera drops (a
    // fisheye pixel outside its circle) and a miss leave object -1 and t = +inf.
    void first_hits(const Tile& tile, TileScratch& s, FirstHits& out) const {
        pixel_order_for(tile, s);
        const std::size_t pixels = static_cast<std::size_t>(tile.width) * tile.height;
        const auto w = static_cast<std::uint32_t>(tile.width);
        // A miss in every pixel of the tile first: a pixel without a ray keeps it.
        for (int y = tile.y0; y < tile.y0 + tile.height; ++y) {
            const std::size_t row = static_cast<std::size_t>(y - out.rect.y0) *
                                        static_cast<std::size_t>(out.rect.width()) +
                                    static_cast<std::size_t>(tile.x0 - out.rect.x0);
            std::fill_n(out.t.begin() + static_cast<std::ptrdiff_t>(row), tile.width,
                        std::numeric_limits<float>::infinity());
            std::fill_n(out.object.begin() + static_cast<std::ptrdiff_t>(row), tile.width,
                        kernels::kNoHit);
        }
        for (std::size_t first = 0; first < pixels; first += ray_chunk_) {
            const std::size_t n = std::min<std::size_t>(ray_chunk_, pixels - first);
            camera_samples(tile, s, first, n, 0, 1);
            s.primary.reserve(n);
            const std::uint32_t count = k_.camera_rays(
                view_, s.samples.view(), static_cast<std::uint32_t>(n), s.primary.view());
            if (count == 0) continue;
            s.hits.reserve(count);
            k_.closest_hit(view_, s.primary.view(), count, scene_.epsilon, s.hits.view());
            for (std::uint32_t r = 0; r < count; ++r) {
                const std::uint32_t p = s.primary.pixel[r];
                const std::size_t at =
                    static_cast<std::size_t>(tile.y0 + static_cast<int>(p / w) - out.rect.y0) *
                        static_cast<std::size_t>(out.rect.width()) +
                    static_cast<std::size_t>(tile.x0 + static_cast<int>(p % w) - out.rect.x0);
                out.t[at] = s.hits.t[r];
                out.object[at] = s.hits.object[r];
            }
        }
    }

  private:
    // The tile's pixels block by block (4 x 2 pixels each), row by row in a block, in
    // s.pixel_order. It depends on the tile's shape alone: built when the shape changes.
    static void pixel_order_for(const Tile& tile, TileScratch& s) {
        if (s.order_width == tile.width && s.order_height == tile.height) return;
        s.pixel_order.clear();
        s.pixel_order.reserve(static_cast<std::size_t>(tile.width) * tile.height);
        for (int by = 0; by < tile.height; by += kBlockHeight)
            for (int bx = 0; bx < tile.width; bx += kBlockWidth)
                for (int y = by; y < std::min(by + kBlockHeight, tile.height); ++y)
                    for (int x = bx; x < std::min(bx + kBlockWidth, tile.width); ++x)
                        s.pixel_order.push_back(
                            {static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y)});
        s.order_width = tile.width, s.order_height = tile.height;
    }

    // Samples [first, first + n) of the tile's stream (pixel_order, each pixel's samples
    // [first_sample, first_sample + per_pixel) in turn) into s.samples, padded to a whole
    // packet with a harmless film position.
    void camera_samples(const Tile& tile, TileScratch& s, std::size_t first, std::size_t n,
                        int first_sample, std::uint32_t per_pixel) const {
        s.samples.reserve(n);
        const bool lens = scene_.camera.type == CameraType::thinlens;
        const bool centers = scene_.spp == 1 && !lens;  // one sample per pixel, at its center
        float *sx = s.samples.x.data(), *sy = s.samples.y.data();
        float *su = s.samples.lens_u.data(), *sv = s.samples.lens_v.data();
        std::uint32_t* spixel = s.samples.pixel.data();
        const TilePixel* pixel = s.pixel_order.data();
        const float* cx = center_x_.data() + tile.x0;
        const float* cy = center_y_.data() + tile.y0;
        const auto w = static_cast<std::uint32_t>(tile.width);
        const auto center_sample = [&](TilePixel p, std::size_t m) {
            sx[m] = cx[p.x];
            sy[m] = cy[p.y];
            su[m] = sv[m] = 0.0f;
            spixel[m] = p.y * w + p.x;
        };
        if (centers) {  // per_pixel == 1
            // Four samples in a row are mostly a row of a 4 x 2 block: four neighbouring
            // columns of one row, copied four at a time (this loop was 3 % of a frame).
            std::size_t m = 0;
            for (; m + 4 <= n; m += 4) {
                const TilePixel p = pixel[first + m];
                const TilePixel q = pixel[first + m + 3];
                if (q.y == p.y && q.x == p.x + 3 && pixel[first + m + 1].x == p.x + 1 &&
                    pixel[first + m + 2].x == p.x + 2) {
                    _mm_storeu_ps(sx + m, _mm_loadu_ps(cx + p.x));
                    _mm_storeu_ps(sy + m, _mm_set1_ps(cy[p.y]));
                    _mm_storeu_ps(su + m, _mm_setzero_ps());
                    _mm_storeu_ps(sv + m, _mm_setzero_ps());
                    const std::uint32_t at = p.y * w + p.x;
                    _mm_storeu_si128(reinterpret_cast<__m128i*>(spixel + m),
                                     _mm_add_epi32(_mm_set1_epi32(static_cast<int>(at)),
                                                   _mm_setr_epi32(0, 1, 2, 3)));
                    continue;
                }
                for (std::size_t k = m; k < m + 4; ++k) center_sample(pixel[first + k], k);
            }
            for (; m < n; ++m) center_sample(pixel[first + m], m);
        } else {
            std::size_t order = first / per_pixel;
            auto k = static_cast<std::uint32_t>(first % per_pixel);
            for (std::size_t m = 0; m < n; ++m) {
                const TilePixel p = pixel[order];
                const int i = tile.x0 + static_cast<int>(p.x),
                          j = tile.y0 + static_cast<int>(p.y);
                const auto ui = static_cast<std::uint32_t>(i);
                const auto uj = static_cast<std::uint32_t>(j);
                const auto sample = static_cast<std::uint32_t>(first_sample) + k;
                const PixelOffset o =
                    pixel_sample_offset(frame_, ui, uj, sample,
                                        static_cast<std::uint32_t>(scene_.spp), scene_.seed);
                sx[m] = film_x(i, o.ox, scene_.width);
                sy[m] = film_y(j, o.oy, scene_.height);
                su[m] = lens ? sample_uniform(frame_, ui, uj, sample, kDimLensU, scene_.seed)
                             : 0.0f;
                sv[m] = lens ? sample_uniform(frame_, ui, uj, sample, kDimLensV, scene_.seed)
                             : 0.0f;
                spixel[m] = p.y * w + p.x;
                if (++k == per_pixel) k = 0, ++order;
            }
        }
        // Up to the stream's capacity for n samples (whole packets and the spare one), not
        // the buffer's: a buffer grown by a larger tile (64x64 after 16x16, the viewer's
        // frameless blocks after whole tiles) had every call pad thousands of samples.
        for (std::size_t m = n; m < stream_capacity(n); ++m) {  // reserve(n) sized it
            sx[m] = sy[m] = su[m] = sv[m] = 0.0f;
            spixel[m] = 0;
        }
    }

    // Traces `count` rays of generation `depth` (primary rays: 0) and, chunk by chunk,
    // depth first, the trees below them; leaves their colors in s.levels[depth].color.
    // Primary rays live on (ε_s, inf), secondary ones on (0, inf).
    void trace_generation(int depth, const kernels::RayStream& rays, std::uint32_t count,
                          TileScratch& s, RayCounts& counts, TileControl& control) const {
        Level& level = s.levels[static_cast<std::size_t>(depth)];
        s.hits.reserve(count);
        s.shadows.reserve(static_cast<std::size_t>(count) * scene_.lights.count);
        level.color.reserve(count);
        level.next.reserve(2 * static_cast<std::size_t>(count));
        level.next_links.reserve(2 * static_cast<std::size_t>(count));

        const float t_min = depth == 0 ? scene_.epsilon : 0.0f;
        k_.closest_hit(view_, rays, count, t_min, s.hits.view());
        const kernels::ShadeCounts shaded =
            k_.shade(view_, kernels::ShadeInput{rays, s.hits.view(), count, depth},
                     kernels::ShadeOutput{level.color.view(), s.shadows.view(),
                                          level.next.view(), level.next_links.view()});
        k_.any_hit(view_, s.shadows.view(), shaded.shadow, s.shadows.occluded.data());
        counts.shadow += shaded.shadow;
        counts.reflected += shaded.reflected;
        counts.refracted += shaded.refracted;
        // Visible light terms join their parent's color in light order.
        add_visible_terms(s.shadows, shaded.shadow, level.color.view());

        // The children, a chunk at a time; a traced child's tail is factor * (the child's
        // color), as the reference's factor * trace(child), so the images agree bit for
        // bit. (Shade never spawns children at max_depth: s.levels has room.)
        const kernels::RayStream next = level.next.view();
        const kernels::ChildLinks links = level.next_links.view();
        for (std::uint32_t first = 0; first < shaded.next; first += ray_chunk_) {
            if (!control.proceed()) return;  // the render throws the colors away
            const std::uint32_t n = std::min(ray_chunk_, shaded.next - first);
            trace_generation(depth + 1, offset(next, first), n, s, counts, control);
            resolve_into_parents(s.levels[static_cast<std::size_t>(depth) + 1].color.view(),
                                 offset(links, first), n, level.color.view());
        }
    }

    const CompiledScene& scene_;
    kernels::SceneView view_;
    const kernels::KernelTable& k_;
    std::uint32_t frame_;
    std::uint32_t ray_chunk_;  // rays traced at once per generation: whole 16-ray packets
    std::vector<float> center_x_, center_y_;
};

// The per-thread tallies of a render's tiles: the rays traced and the largest scratch.
struct TileTallies {
    tbb::enumerable_thread_specific<RayCounts> counts;
    tbb::enumerable_thread_specific<std::uint64_t> scratch_bytes{std::uint64_t{0}};

    void add_to(RenderResult& result) const {
        for (const RayCounts& c : counts) result.rays += c;
        for (std::uint64_t bytes : scratch_bytes)
            result.scratch_bytes = std::max(result.scratch_bytes, bytes);
    }
};

// Traces tiles tile_at(0) .. tile_at(count - 1) with `tracer` into `target`, in parallel in
// the calling thread's arena, until `control` says to stop.
template <class TileAt>
void trace_tiles(const PacketTracer& tracer, const RenderTarget& target, int count,
                 const TileAt& tile_at, TileControl& control, TileTallies& tallies) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, count, 1),
        [&](const tbb::blocked_range<int>& range) {
            TileScratch& s = scratch_for_thread();
            RayCounts& c = tallies.counts.local();
            for (int t = range.begin(); t < range.end(); ++t) {
                if (!control.proceed()) return;
                const Tile tile = tile_at(t);
                if (!tracer.render_tile(tile, s, target, c, control)) break;
                control.done(static_cast<std::uint64_t>(tile.width) *
                             static_cast<std::uint64_t>(tile.height));
            }
            std::uint64_t& bytes = tallies.scratch_bytes.local();
            bytes = std::max(bytes, s.bytes());
        },
        tbb::auto_partitioner());
}

// RenderOptions::ray_chunk as the tracer takes it: whole 16-ray packets, 0 the default.
std::uint32_t ray_chunk_of(const RenderOptions& options) {
    return options.ray_chunk == 0
               ? kDefaultRayChunk
               : (std::max<std::uint32_t>(options.ray_chunk, 1u) + 15u) / 16u * 16u;
}

// Where a frame's BVH comes from: built for this frame (as options.accel says), or
// prepared beforehand (`prepared`, nullptr when the prepared scene is traced brute force).
struct FrameTree {
    bool is_prepared = false;
    const SphereBvh* prepared = nullptr;
};

RenderResult render_frame(const CompiledScene& scene, FrameTree tree,
                          const RenderOptions& options, const kernels::KernelTable& table) {
    const auto start = std::chrono::steady_clock::now();
    RenderResult result;
    // The crop and the sample range (render/crop.h), checked before any work. Tiles are
    // laid from the crop's corner; a pixel's value depends on neither.
    const PixelRect rect = render_rect(options, scene.width, scene.height);
    const SampleRange sample_range = render_sample_range(options, scene.spp, rect);
    // Every pixel of the rectangle is written by its tile.
    // A frame in fresh storage (not a spare of the right size) has its pages mapped first.
    const PixelRect full{0, 0, scene.width, scene.height};
    const bool fresh_frame =
        options.spare_image == nullptr || !fits_rgb_storage(*options.spare_image, rect);
    result.image = make_rgb_image(
        rect, full, options.spare_image != nullptr ? std::move(*options.spare_image) : Image());
    if (options.spare_image != nullptr) *options.spare_image = Image();
    RenderTarget target{result.image, rect, sample_range};
    if (options.samples) {
        result.sample_sums = make_rgb_image(rect, full);
        target.start_sums = sample_range.begin > 0 ? options.sample_sums : nullptr;
        target.sums = &result.sample_sums;
    }
    const TileGrid grid(rect, options);
    TileTallies tallies;
    TileControl control(options);

    // The spheres' BVH: the prepared one, or (options.accel) one built on the render's
    // threads and timed with it.
    SphereBvh bvh;
    const bool build_bvh =
        !tree.is_prepared && accel_uses_bvh(options.accel, scene.spheres.count);
    const auto render_tiles = [&] {
        if (fresh_frame) populate_frame(result.image);
        if (build_bvh) bvh = build_sphere_bvh(scene.spheres);
        const PacketTracer tracer(
            scene, table, options.frame,
            tree.is_prepared ? tree.prepared : (build_bvh ? &bvh : nullptr),
            ray_chunk_of(options));
        trace_tiles(
            tracer, target, grid.count(), [&](int t) { return grid.at(t); }, control, tallies);
    };
    run_with_threads(options.threads, render_tiles);
    control.finish();
    tallies.add_to(result);
    result.bvh_seconds = build_bvh ? bvh.build_seconds : 0.0;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace

RenderResult render_packet(const CompiledScene& scene, const RenderOptions& options, Isa isa) {
    return render_packet(scene, options, kernel_table(resolve_isa(isa)));
}

RenderResult render_packet(const CompiledScene& scene, const RenderOptions& options,
                           const kernels::KernelTable& table) {
    return render_frame(scene, FrameTree{}, options, table);
}

RenderResult render_packet(const PreparedScene& scene, const RenderOptions& options, Isa isa) {
    return render_frame(scene.compiled(), FrameTree{true, scene.bvh()}, options,
                        kernel_table(resolve_isa(isa)));
}

FirstHits trace_first_hits(const PreparedScene& prepared, const RenderOptions& options,
                           Isa isa) {
    const CompiledScene& scene = prepared.compiled();
    FirstHits out;
    out.rect = render_rect(options, scene.width, scene.height);
    // Sized, not filled: each tile writes its pixels' misses first (first_hits), on the
    // render's threads.
    out.t.resize(out.rect.pixel_count());
    out.object.resize(out.rect.pixel_count());
    const kernels::KernelTable& table = kernel_table(resolve_isa(isa));
    const TileGrid grid(out.rect, options);
    run_with_threads(options.threads, [&] {
        const PacketTracer tracer(scene, table, options.frame, prepared.bvh(),
                                  ray_chunk_of(options));
        tbb::parallel_for(tbb::blocked_range<int>(0, grid.count(), 1),
                          [&](const tbb::blocked_range<int>& range) {
                              TileScratch& s = scratch_for_thread();
                              for (int t = range.begin(); t < range.end(); ++t)
                                  tracer.first_hits(grid.at(t), s, out);
                          });
    });
    return out;
}

RenderResult render_packet(const Scene& scene, const RenderOptions& options, Isa isa) {
    const auto start = std::chrono::steady_clock::now();
    const CompiledScene compiled = compile_scene(scene);
    RenderResult result = render_packet(compiled, options, isa);
    result.compile_seconds = compiled.compile_seconds;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

PreparedScene::PreparedScene(const Scene& scene, Accel accel, int threads)
    : compiled_(compile_scene(scene)),
      use_bvh_(accel_uses_bvh(accel, compiled_.spheres.count)),
      threads_(threads) {
    if (use_bvh_) build();
}

void PreparedScene::build() {
    run_with_threads(threads_, [&] { bvh_ = build_sphere_bvh(compiled_.spheres); });
    built_cost_ = -1.0;    // measured by the first update of this tree, before its refit
    leaf_sphere_.clear();  // found by the first refit of this tree
}

PreparedScene::Update PreparedScene::update(const Scene& posed) {
    const auto start = std::chrono::steady_clock::now();
    Update u;
    set_camera(posed.camera);
    if (use_bvh_ && built_cost_ < 0.0) built_cost_ = sphere_bvh_cost(bvh_);
    if (use_bvh_ && leaf_sphere_.empty()) {
        // Leaf slot i holds the sphere of file index bvh_.object[i]: its compiled index.
        std::vector<std::uint32_t> compiled_index(compiled_.objects.count, 0);
        for (std::uint32_t s = 0; s < compiled_.spheres.count; ++s)
            compiled_index[compiled_.spheres.object[s]] = s;
        leaf_sphere_.resize(bvh_.sphere_count);
        for (std::uint32_t i = 0; i < bvh_.sphere_count; ++i)
            leaf_sphere_[i] = compiled_index[bvh_.object[i]];
    }
    const auto write_and_refit = [&] {
        update_compiled_spheres(compiled_, posed);
        if (use_bvh_) refit_sphere_bvh(bvh_, compiled_.spheres, leaf_sphere_);
    };
    // One arena for both steps, and none below kArenaUpdateSpheres spheres: their update
    // is tens of microseconds of work, less than waking the workers of an arena (1024
    // spheres took 195 us in two arenas against Embree's 23 us refit; the rule:
    // bench/README.md, "Refit").
    if (compiled_.spheres.count < kArenaUpdateSpheres)
        write_and_refit();
    else
        run_with_threads(threads_, write_and_refit);
    if (use_bvh_) {
        u.cost_growth = built_cost_ > 0.0 ? sphere_bvh_cost(bvh_) / built_cost_ : 1.0;
        if (u.cost_growth > kRefitCostLimit) {
            build();
            u.rebuilt = true;
        }
    }
    u.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return u;
}

RenderResult render_packet_blocks(const PreparedScene& prepared,
                                  std::span<const PixelRect> blocks, Image& target,
                                  const RenderOptions& options, Isa isa) {
    const auto start = std::chrono::steady_clock::now();
    const CompiledScene& scene = prepared.compiled();
    check_block_render(blocks, target, scene.width, scene.height, options);
    const kernels::KernelTable& table = kernel_table(resolve_isa(isa));
    RenderResult result;
    result.image.display_window = PixelRect{0, 0, scene.width, scene.height};
    const RenderTarget out{target, PixelRect{0, 0, scene.width, scene.height},
                           SampleRange{0, scene.spp}};
    TileTallies tallies;
    TileControl control(options);
    run_with_threads(options.threads, [&] {
        const PacketTracer tracer(scene, table, options.frame, prepared.bvh(),
                                  ray_chunk_of(options));
        trace_tiles(
            tracer, out, static_cast<int>(blocks.size()),
            [&](int t) {
                const PixelRect& b = blocks[static_cast<std::size_t>(t)];
                return Tile{b.x0, b.y0, b.width(), b.height()};
            },
            control, tallies);
    });
    control.finish();
    tallies.add_to(result);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace octray
