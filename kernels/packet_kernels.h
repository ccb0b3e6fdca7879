// The packet kernels, templated on the xsimd architecture. Included ONLY by the per-ISA
// translation units (kernels_avx2.cpp, kernels_sse41.cpp, kernels_sse2.cpp), each of which
// defines OCTRAY_KERNEL_NAMESPACE first so that every function here lands in a namespace of
// its own: nothing compiled with -mavx2 can be merged by the linker into code that runs on
// an SSE2-only CPU (kernels/README.md, "the ODR rule"). For the same reason this file calls
// no non-template inline code from shared headers: only xsimd (templated on the
// architecture), C library functions (<math.h>: sqrtf, powf, sinf, cosf, atan2f) and the
// plain-data structs of kernels/kernel_types.h.
//
// Every formula mirrors render/reference.cpp operation by operation (same operands, same
// order; -ffp-contract=off keeps the compiler from fusing), so a ray traced here has the
// same bits as the reference's. Comments name the reference's expression where the order
// matters. Transcendental functions (pow, sin, cos, atan2) are the C library's, per lane,
// as in the reference: xsimd's own versions differ by ulps.
//
// Packets are 8 rays (kPacketWidth). A kernel walks a stream in packets; a packet is
// K = 8 / batch::size registers (one on AVX2, two on SSE).

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <immintrin.h>
#include <math.h>

#include <cstdint>
#include <type_traits>
#include <xsimd/xsimd.hpp>

#include "kernels/kernel_types.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// A new ray whose weight is below this in every channel is not traced (reference:
// kMinRayWeight).
constexpr float kMinRayWeight = 1e-3f;
// |V.N| below this is a plane miss (reference: kPlaneParallelEpsilon).
constexpr float kPlaneParallelEpsilon = 1e-12f;
// 2 * std::numbers::pi_v<float>, as the reference's thin lens computes it.
constexpr float kTwoPi = 2.0f * 3.14159265358979323846f;
constexpr float kInf = __builtin_inff();

template <class F>
struct V3 {
    F x, y, z;
};

// Vec3 arithmetic, component by component (core/vec3.h's order).
template <class F>
V3<F> add(const V3<F>& a, const V3<F>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class F>
V3<F> sub(const V3<F>& a, const V3<F>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class F>
V3<F> neg(const V3<F>& a) {
    return {-a.x, -a.y, -a.z};
}
template <class F>
V3<F> mul(const V3<F>& a, const F& s) {
    return {a.x * s, a.y * s, a.z * s};
}
template <class F>
V3<F> div(const V3<F>& a, const F& s) {
    return {a.x / s, a.y / s, a.z / s};
}
// Component-wise product (Rgb * Rgb).
template <class F>
V3<F> hadamard(const V3<F>& a, const V3<F>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
// Summed left to right: (x*x + y*y) + z*z.
template <class F>
F dot(const V3<F>& a, const V3<F>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
// Divides by the length, as core/vec3.h's normalize does.
template <class F>
V3<F> normalize(const V3<F>& a) {
    const F len = xsimd::sqrt(dot(a, a));
    return div(a, len);
}
template <class F, class M>
V3<F> select(const M& m, const V3<F>& a, const V3<F>& b) {
    return {xsimd::select(m, a.x, b.x), xsimd::select(m, a.y, b.y), xsimd::select(m, a.z, b.z)};
}
// core/color.h's max_component: (r > g ? r : g), then (m > b ? m : b).
template <class F>
F max_component(const V3<F>& c) {
    const F m = xsimd::select(c.x > c.y, c.x, c.y);
    return xsimd::select(m > c.z, m, c.z);
}
template <class F>
V3<F> broadcast(const float v[3]) {
    return {F(v[0]), F(v[1]), F(v[2])};
}
template <class F>
V3<F> load3(const float* x, const float* y, const float* z, std::uint32_t i) {
    return {F::load_aligned(x + i), F::load_aligned(y + i), F::load_aligned(z + i)};
}
template <class F>
void store3(const V3<F>& v, float* x, float* y, float* z, std::uint32_t i) {
    v.x.store_aligned(x + i);
    v.y.store_aligned(y + i);
    v.z.store_aligned(z + i);
}

// Ray-sphere in the form that keeps its digits for small, distant spheres (reference:
// intersect_sphere, which derives it; Ray Tracing Gems ch. 7). Two steps, so that a loop
// can skip the roots when no lane has any: sphere_quadratic gives b = O'.V,
// c' = O'.O' - r^2 and disc = a (r^2 - l.l) with l = O' - (b/a) V; sphere_roots the two
// roots, sorted, from q = -b - sign(b) sqrt(disc): q/a and c'/q (q/a alone when q = 0).
// A negative or NaN discriminant gives NaN roots: every comparison with them fails.
// Forced inline: GCC kept them as calls in the leaf loops (4 % of a frame, perf).
template <class F>
struct SphereQuadratic {
    F b, c, disc;
};

template <class F>
[[gnu::always_inline]] inline SphereQuadratic<F> sphere_quadratic(const V3<F>& oc,
                                                                  const V3<F>& d, const F& a,
                                                                  const F& r2) {
    const F b = dot(oc, d);
    const V3<F> l = sub(oc, mul(d, b / a));
    return {b, dot(oc, oc) - r2, a * (r2 - dot(l, l))};
}

template <class F>
struct SphereRoots {
    F t_near, t_far;
};

template <class F>
[[gnu::always_inline]] inline SphereRoots<F> sphere_roots(const SphereQuadratic<F>& s,
                                                          const F& a) {
    const F zero(0.0f);
    const F root = xsimd::sqrt(s.disc);
    const F q = xsimd::select(s.b >= zero, -s.b - root, -s.b + root);
    const F t_q = q / a;
    const F t_c = xsimd::select(q != zero, s.c / q, t_q);
    const auto swap = t_c < t_q;
    return {xsimd::select(swap, t_c, t_q), xsimd::select(swap, t_q, t_c)};
}

// Lanes [base, base + size) that lie below `count`.
template <class F>
auto live_lanes(std::uint32_t base, std::uint32_t count) {
    alignas(64) static constexpr float kIota[16] = {0, 1, 2,  3,  4,  5,  6,  7,
                                                    8, 9, 10, 11, 12, 13, 14, 15};
    const std::uint32_t left = count - base;
    const float limit = static_cast<float>(left < F::size ? left : F::size);
    return F::load_aligned(kIota) < F(limit);
}

// The lanes of a mask as 0/1 flags in memory, for the per-lane loops (compaction, libm).
template <class F, class M>
void mask_to_flags(const M& m, float* flags) {
    xsimd::select(m, F(1.0f), F(0.0f)).store_aligned(flags);
}

// The object (or material) each lane reads, and whether they are all the same: coherent
// packets (a 4x2 pixel block on one sphere) then load each field once and broadcast it.
struct LaneIndex {
    alignas(64) std::int32_t index[kPacketWidth];
    bool uniform;
};

// base[index[i]] per lane, as float (T: float, or a small unsigned count or flag). AVX2
// gathers in one instruction; SSE builds the register from four scalar loads. Neither
// writes lanes to memory to load them back as a whole register (a store-forwarding stall).
template <class F, class T>
F gather(const T* base, const LaneIndex& ix) {
    if (ix.uniform) return F(static_cast<float>(base[ix.index[0]]));
    if constexpr (F::size == 8) {
        const __m256i index = _mm256_load_si256(reinterpret_cast<const __m256i*>(ix.index));
        if constexpr (std::is_same_v<T, float>)
            return _mm256_i32gather_ps(base, index, 4);
        else
            return _mm256_cvtepi32_ps(
                _mm256_i32gather_epi32(reinterpret_cast<const int*>(base), index, 4));
    } else {
        static_assert(F::size == 4);
        return _mm_setr_ps(
            static_cast<float>(base[ix.index[0]]), static_cast<float>(base[ix.index[1]]),
            static_cast<float>(base[ix.index[2]]), static_cast<float>(base[ix.index[3]]));
    }
}

// ---------------------------------------------------------------------------------------
// Stream compaction: the lanes of a mask packed to the front of an output stream, in lane
// order. AVX2 permutes whole registers (vpermps with an index vector from a 256-entry
// table, then one unaligned store of all 8 lanes: the caller's streams have a spare
// packet at the end); SSE copies lane by lane.
struct CompressTable {
    std::uint8_t lanes[256][8];
};
constexpr CompressTable make_compress_table() {
    CompressTable t{};
    for (int m = 0; m < 256; ++m) {
        int n = 0;
        for (int i = 0; i < 8; ++i)
            if (m & (1 << i)) t.lanes[m][n++] = static_cast<std::uint8_t>(i);
    }
    return t;
}
alignas(64) inline constexpr CompressTable kCompressTable = make_compress_table();

template <class F>
struct Compaction {
    std::uint32_t bits;   // bit i: lane i is selected
    std::uint32_t count;  // selected lanes
    // The selected lanes in order, then zeros (kCompressTable's row for `bits`).
    const std::uint8_t* lanes() const { return kCompressTable.lanes[bits]; }
};

// Bit i set when lane i of the mask is (movmskps).
template <class F, class M>
std::uint32_t mask_bits(const M& m) {
    if constexpr (F::size == 8) {
        return static_cast<std::uint32_t>(_mm256_movemask_ps(static_cast<__m256>(m)));
    } else {
        return static_cast<std::uint32_t>(_mm_movemask_ps(static_cast<__m128>(m)));
    }
}

template <class F, class M>
Compaction<F> compaction(const M& m) {
    const std::uint32_t bits = mask_bits<F>(m);
    return {bits, static_cast<std::uint32_t>(__builtin_popcount(bits))};
}

// The permutation that packs a compaction's lanes to the front, widened from the byte
// table straight into a register (no store and reload of a lane array in between).
template <class F>
__m256i compaction_index(std::uint32_t bits) {
    static_assert(F::size == 8, "AVX2 only");
    return _mm256_cvtepu8_epi32(
        _mm_loadl_epi64(reinterpret_cast<const __m128i*>(kCompressTable.lanes[bits])));
}

// Writes the selected lanes of v to dst[0, count); with AVX2 also scribbles on
// dst[count, 8).
template <class F>
void store_compacted(const Compaction<F>& c, const F& v, float* dst) {
    if constexpr (F::size == 8) {
        _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(v, compaction_index<F>(c.bits)));
    } else {
        alignas(64) float lanes[F::size];
        v.store_aligned(lanes);
        const std::uint8_t* selected = c.lanes();
        for (std::uint32_t k = 0; k < c.count; ++k) dst[k] = lanes[selected[k]];
    }
}
template <class F>
void store_compacted(const Compaction<F>& c, const V3<F>& v, float* x, float* y, float* z,
                     std::uint32_t at) {
    store_compacted(c, v.x, x + at);
    store_compacted(c, v.y, y + at);
    store_compacted(c, v.z, z + at);
}
// base + lane for each selected lane, times `scale`, plus `offset`; with AVX2 also
// scribbles on dst[count, 8).
template <class F>
void store_compacted_slots(const Compaction<F>& c, std::uint32_t base, std::uint32_t scale,
                           std::uint32_t offset, std::uint32_t* dst) {
    if constexpr (F::size == 8) {
        const __m256i lane = compaction_index<F>(c.bits);
        const __m256i slot = _mm256_add_epi32(
            _mm256_mullo_epi32(
                _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(base)), lane),
                _mm256_set1_epi32(static_cast<int>(scale))),
            _mm256_set1_epi32(static_cast<int>(offset)));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst), slot);
    } else {
        const std::uint8_t* selected = c.lanes();
        for (std::uint32_t k = 0; k < c.count; ++k)
            dst[k] = (base + selected[k]) * scale + offset;
    }
}
// `value` in dst[0, count); with AVX2 also scribbles on dst[count, 8).
template <class F>
void store_count(const Compaction<F>& c, float value, float* dst) {
    if constexpr (F::size == 8) {
        _mm256_storeu_ps(dst, _mm256_set1_ps(value));
    } else {
        for (std::uint32_t k = 0; k < c.count; ++k) dst[k] = value;
    }
}

// Parity of floor(x) as 0 or 1 (reference: floor_parity): f - 2 floor(f / 2).
template <class F>
F floor_parity(const F& x) {
    const F f = xsimd::floor(x);
    return f - F(2.0f) * xsimd::floor(f * F(0.5f));
}

// Background along a direction (reference: ReferenceTracer::background).
template <class F>
V3<F> background(const SceneView& s, const V3<F>& direction) {
    if (s.background == BackgroundKind::constant) return broadcast<F>(s.bg_color);
    const F t = F(0.5f) * (dot(normalize(direction), broadcast<F>(s.bg_up)) + F(1.0f));
    const V3<F> bottom = broadcast<F>(s.bg_bottom), top = broadcast<F>(s.bg_top);
    // mix(a, b, t) = a + (b - a) * t
    return add(bottom, mul(sub(top, bottom), t));
}

// ---------------------------------------------------------------------------------------
// Camera: film positions to primary rays (reference: ReferenceTracer::camera_ray).
// Returns the number of rays written; a fisheye sample outside the image circle has no
// ray, so the fisheye compacts its packets, every other camera writes one ray per sample.
template <class Arch>
std::uint32_t camera_rays(const SceneView& s, const CameraSamples& in, std::uint32_t count,
                          const RayStream& out) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const V3<F> eye = broadcast<F>(s.eye), ln = broadcast<F>(s.ln);
    const V3<F> u_hat = broadcast<F>(s.u_hat), v_hat = broadcast<F>(s.v_hat);
    const V3<F> u = broadcast<F>(s.u), v = broadcast<F>(s.v);
    std::uint32_t written = 0;
    for (std::uint32_t base = 0; base < count; base += W) {
        const std::uint32_t lanes = count - base < W ? count - base : W;
        const F x = F::load_aligned(in.x + base), y = F::load_aligned(in.y + base);
        V3<F> origin = eye, direction;
        auto valid = live_lanes<F>(base, count);
        switch (s.camera) {
            case CameraKind::pinhole:
                // normalize(ln + u*x + v*y)
                direction = normalize(add(add(ln, mul(u, x)), mul(v, y)));
                break;
            case CameraKind::orthographic:
                // eye + u_hat*(x*half_width) + v_hat*(y*half_height), along ln
                origin = add(add(eye, mul(u_hat, x * F(s.half_width))),
                             mul(v_hat, y * F(s.half_height)));
                direction = ln;
                break;
            case CameraKind::thinlens: {
                const V3<F> d = normalize(add(add(ln, mul(u, x)), mul(v, y)));
                const V3<F> focus = add(eye, mul(d, F(s.focus_distance) / dot(d, ln)));
                // r = aperture * sqrt(lu), phi = 2 pi lv; cos / sin from libm per lane.
                const F r = F(s.aperture) * xsimd::sqrt(F::load_aligned(in.lens_u + base));
                const F phi = F(kTwoPi) * F::load_aligned(in.lens_v + base);
                alignas(64) float phis[W], coss[W] = {}, sins[W] = {};
                phi.store_aligned(phis);
                for (std::uint32_t i = 0; i < lanes; ++i) {
                    coss[i] = cosf(phis[i]);
                    sins[i] = sinf(phis[i]);
                }
                origin = add(add(eye, mul(u_hat, r * F::load_aligned(coss))),
                             mul(v_hat, r * F::load_aligned(sins)));
                direction = normalize(sub(focus, origin));
                break;
            }
            case CameraKind::fisheye: {
                // Equidistant: psi = r * fov/2 from ln, towards phi = atan2(y/a, x).
                const F ya = y / F(s.aspect);
                const F r = xsimd::sqrt(x * x + ya * ya);
                valid = valid && !(r > F(1.0f));
                const F psi = r * F(s.half_fov_radians);
                alignas(64) float xs[W], yas[W], psis[W], flags[W];
                alignas(64) float cos_psi[W] = {}, sin_psi[W] = {}, cos_phi[W] = {},
                                  sin_phi[W] = {};
                x.store_aligned(xs);
                ya.store_aligned(yas);
                psi.store_aligned(psis);
                mask_to_flags<F>(valid, flags);
                for (std::uint32_t i = 0; i < lanes; ++i) {
                    if (flags[i] == 0.0f) continue;
                    const float phi = atan2f(yas[i], xs[i]);
                    cos_psi[i] = cosf(psis[i]);
                    sin_psi[i] = sinf(psis[i]);
                    cos_phi[i] = cosf(phi);
                    sin_phi[i] = sinf(phi);
                }
                // ln*cos(psi) + (u_hat*cos(phi) + v_hat*sin(phi))*sin(psi)
                direction = add(mul(ln, F::load_aligned(cos_psi)),
                                mul(add(mul(u_hat, F::load_aligned(cos_phi)),
                                        mul(v_hat, F::load_aligned(sin_phi))),
                                    F::load_aligned(sin_psi)));
                break;
            }
        }
        if (s.camera != CameraKind::fisheye) {
            store3(origin, out.ox, out.oy, out.oz, base);
            store3(direction, out.dx, out.dy, out.dz, base);
            for (std::uint32_t i = 0; i < W; ++i) {
                out.wr[base + i] = out.wg[base + i] = out.wb[base + i] = 1.0f;
                out.pixel[base + i] = i < lanes ? in.pixel[base + i] : 0u;
            }
            written += lanes;
            continue;
        }
        // Fisheye: compact the samples inside the image circle.
        alignas(64) float flags[W], o[3][W], d[3][W];
        mask_to_flags<F>(valid, flags);
        store3(origin, o[0], o[1], o[2], 0);
        store3(direction, d[0], d[1], d[2], 0);
        for (std::uint32_t i = 0; i < lanes; ++i) {
            if (flags[i] == 0.0f) continue;
            out.ox[written] = o[0][i], out.oy[written] = o[1][i], out.oz[written] = o[2][i];
            out.dx[written] = d[0][i], out.dy[written] = d[1][i], out.dz[written] = d[2][i];
            out.wr[written] = out.wg[written] = out.wb[written] = 1.0f;
            out.pixel[written] = in.pixel[base + i];
            ++written;
        }
    }
    return written;
}

// ---------------------------------------------------------------------------------------
// Planes, for one register of rays: closest hit with ties to the lower file index, and
// occlusion on (0, t_max). Shared by the brute-force kernels and the BVH traversal
// (kernels/bvh_kernels.h): planes stay outside the BVH.
template <class F>
void closest_planes(const SceneView& s, const V3<F>& o, const V3<F>& d, const F& tmin,
                    F& best_t, F& best_id) {
    for (std::uint32_t i = 0; i < s.plane_count; ++i) {
        // t = (d - O.N) / (V.N), d = P0.N; |V.N| < 1e-12 misses.
        const V3<F> n{F(s.plane_nx[i]), F(s.plane_ny[i]), F(s.plane_nz[i])};
        const F pd(s.plane_d[i]);
        const F id(static_cast<float>(s.plane_object[i]));
        const F denom = dot(d, n);
        const F t = (pd - dot(o, n)) / denom;
        const auto nearer = t < best_t || (t == best_t && id < best_id);
        const auto hit = xsimd::abs(denom) >= F(kPlaneParallelEpsilon) && t > tmin && nearer;
        best_t = xsimd::select(hit, t, best_t);
        best_id = xsimd::select(hit, id, best_id);
    }
}

template <class F>
auto any_plane(const SceneView& s, const V3<F>& o, const V3<F>& d, const F& t_max) {
    auto occluded = F(0.0f) != F(0.0f);  // all false
    for (std::uint32_t i = 0; i < s.plane_count; ++i) {
        const V3<F> n{F(s.plane_nx[i]), F(s.plane_ny[i]), F(s.plane_nz[i])};
        const F pd(s.plane_d[i]);
        const F denom = dot(d, n);
        const F t = (pd - dot(o, n)) / denom;
        occluded = occluded ||
                   (xsimd::abs(denom) >= F(kPlaneParallelEpsilon) && t > F(0.0f) && t < t_max);
    }
    return occluded;
}

// ---------------------------------------------------------------------------------------
// Closest hit over all spheres and planes, brute force (reference:
// ReferenceTracer::intersect); closest_hit() in kernels/bvh_kernels.h calls it when the
// scene has no BVH.
// Spheres are broadcast one at a time against the packet. An object's candidate is its
// first root above t_min; the hit is the smallest candidate, ties to the lower file index
// (the reference walks objects in file order and keeps a hit only when strictly nearer).
template <class Arch>
void closest_hit_all(const SceneView& s, const RayStream& rays, std::uint32_t count,
                     float t_min, const HitStream& hits) {
    using F = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kPacketWidth / W;
    const F tmin(t_min);
    for (std::uint32_t base = 0; base < count; base += kPacketWidth) {
        V3<F> o[K], d[K];
        F a[K], best_t[K], best_id[K];
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = base + k * W;
            o[k] = load3<F>(rays.ox, rays.oy, rays.oz, at);
            d[k] = load3<F>(rays.dx, rays.dy, rays.dz, at);
            a[k] = dot(d[k], d[k]);
            best_t[k] = F(kInf);
            best_id[k] = F(-1.0f);
        }
        for (std::uint32_t i = 0; i < s.sphere_count; ++i) {
            const V3<F> c{F(s.sphere_cx[i]), F(s.sphere_cy[i]), F(s.sphere_cz[i])};
            const F r2(s.sphere_r2[i]);
            SphereQuadratic<F> quad[K];
            M any_root = F(0.0f) != F(0.0f);  // all false
            for (std::uint32_t k = 0; k < K; ++k) {
                quad[k] = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                any_root = any_root || quad[k].disc >= F(0.0f);
            }
            if (xsimd::none(any_root)) continue;
            const F id(static_cast<float>(s.sphere_object[i]));
            for (std::uint32_t k = 0; k < K; ++k) {
                const auto [t_near, t_far] = sphere_roots(quad[k], a[k]);
                const M near_ok = t_near > tmin && t_near < best_t[k];
                const M far_ok = t_far > tmin && t_far < best_t[k];
                const M hit = near_ok || far_ok;
                best_t[k] =
                    xsimd::select(hit, xsimd::select(near_ok, t_near, t_far), best_t[k]);
                best_id[k] = xsimd::select(hit, id, best_id[k]);
            }
        }
        for (std::uint32_t k = 0; k < K; ++k)
            closest_planes(s, o[k], d[k], tmin, best_t[k], best_id[k]);
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = base + k * W;
            best_t[k].store_aligned(hits.t + at);
            xsimd::to_int(best_id[k]).store_aligned(hits.object + at);  // exact: ids < 2^24
        }
    }
}

// ---------------------------------------------------------------------------------------
// Any hit for shadow rays on (0, t_max), brute force (reference: ReferenceTracer::occluded);
// any_hit() in kernels/bvh_kernels.h calls it when the scene has no BVH. A packet
// stops testing objects once every live lane is occluded. occluded[i] is 1 or 0.
template <class Arch>
void any_hit_all(const SceneView& s, const ShadowStream& rays, std::uint32_t count,
                 std::uint32_t* occluded) {
    using F = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kPacketWidth / W;
    const F zero(0.0f);
    for (std::uint32_t base = 0; base < count; base += kPacketWidth) {
        V3<F> o[K], d[K];
        F a[K], t_max[K];
        M done[K];  // occluded, or a dead lane
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = base + k * W;
            o[k] = load3<F>(rays.ox, rays.oy, rays.oz, at);
            d[k] = load3<F>(rays.dx, rays.dy, rays.dz, at);
            t_max[k] = F::load_aligned(rays.t_max + at);
            a[k] = dot(d[k], d[k]);
            done[k] = at < count ? !live_lanes<F>(at, count) : (zero == zero);
        }
        const auto all_done = [&] {
            for (std::uint32_t k = 0; k < K; ++k)
                if (!xsimd::all(done[k])) return false;
            return true;
        };
        for (std::uint32_t i = 0; i < s.sphere_count && !all_done(); ++i) {
            const V3<F> c{F(s.sphere_cx[i]), F(s.sphere_cy[i]), F(s.sphere_cz[i])};
            const F r2(s.sphere_r2[i]);
            SphereQuadratic<F> quad[K];
            M any_root = zero != zero;
            for (std::uint32_t k = 0; k < K; ++k) {
                quad[k] = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                any_root = any_root || (quad[k].disc >= zero && !done[k]);
            }
            if (xsimd::none(any_root)) continue;
            for (std::uint32_t k = 0; k < K; ++k) {
                const auto [t_near, t_far] = sphere_roots(quad[k], a[k]);
                done[k] = done[k] || (t_near > zero && t_near < t_max[k]) ||
                          (t_far > zero && t_far < t_max[k]);
            }
        }
        if (!all_done())
            for (std::uint32_t k = 0; k < K; ++k)
                done[k] = done[k] || any_plane(s, o[k], d[k], t_max[k]);
        // Dead lanes come out as 1; nobody reads them.
        for (std::uint32_t k = 0; k < K; ++k)
            xsimd::to_int(xsimd::select(done[k], F(1.0f), zero))
                .store_aligned(reinterpret_cast<std::int32_t*>(occluded + base + k * W));
    }
}

// ---------------------------------------------------------------------------------------
// Shading (reference: ReferenceTracer::shade and trace's miss branch). Per ray of the
// generation: the ambient term (or the background on a miss), one shadow ray per light in
// front of the surface carrying that light's term, the mirror and refracted rays that are
// traced, and the factor * background tails of those cut off by depth or weight.
template <class Arch>
ShadeCounts shade(const SceneView& s, const ShadeInput& in, const ShadeOutput& out) {
    using F = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const F zero(0.0f), one(1.0f), eps(s.epsilon);
    const bool children_within_depth = in.depth + 1 <= s.max_depth;
    const RayStream& rays = in.rays;
    const SurfaceColor& sc = out.color;
    ShadeCounts counts{0, 0, 0, 0};

    for (std::uint32_t base = 0; base < in.count; base += W) {
        // Lanes that missed (or are dead) read the first hit lane's object: always a valid
        // entry, and a coherent packet stays uniform. Ids travel as exact floats (< 2^24).
        using I = xsimd::batch<std::int32_t, Arch>;
        const F raw_id = xsimd::select(live_lanes<F>(base, in.count),
                                       xsimd::to_float(I::load_aligned(in.hits.object + base)),
                                       F(static_cast<float>(kNoHit)));
        const M hit = raw_id >= zero;
        const std::uint32_t hit_bits = mask_bits<F>(hit);
        const bool all_hit = hit_bits == (1u << W) - 1;
        F id = raw_id;
        if (hit_bits != 0 && !all_hit) {
            alignas(64) float lanes[W];
            raw_id.store_aligned(lanes);
            id = xsimd::select(hit, raw_id, F(lanes[__builtin_ctz(hit_bits)]));
        }
        LaneIndex ids;
        xsimd::to_int(id).store_aligned(ids.index);
        ids.uniform = xsimd::all(id == F(static_cast<float>(ids.index[0])));
        const V3<F> o = load3<F>(rays.ox, rays.oy, rays.oz, base);
        const V3<F> d = load3<F>(rays.dx, rays.dy, rays.dz, base);
        const V3<F> weight = load3<F>(rays.wr, rays.wg, rays.wb, base);
        // What a miss sees (not needed when every lane hit).
        const V3<F> sky = all_hit ? V3<F>{zero, zero, zero} : background(s, d);
        if (xsimd::none(hit)) {
            store3(sky, sc.local_r, sc.local_g, sc.local_b, base);
            store3(V3<F>{zero, zero, zero}, sc.tail_reflect_r, sc.tail_reflect_g,
                   sc.tail_reflect_b, base);
            store3(V3<F>{zero, zero, zero}, sc.tail_refract_r, sc.tail_refract_g,
                   sc.tail_refract_b, base);
            continue;
        }

        // Hit point and geometric normal (reference: ReferenceTracer::intersect): sphere
        // normalize(P - c), or -V^ for a hit at the very center; plane N.
        const F t = F::load_aligned(in.hits.t + base);
        const V3<F> p = add(o, mul(d, t));
        const M is_plane = gather<F>(s.object_is_plane, ids) != zero;
        const V3<F> center{gather<F>(s.object_cx, ids), gather<F>(s.object_cy, ids),
                           gather<F>(s.object_cz, ids)};
        const V3<F> plane_n{gather<F>(s.object_nx, ids), gather<F>(s.object_ny, ids),
                            gather<F>(s.object_nz, ids)};
        const V3<F> v_hat = normalize(d);
        const V3<F> pc = sub(p, center);
        const V3<F> sphere_n = select(dot(pc, pc) > zero, normalize(pc), neg(v_hat));
        const V3<F> normal = select(is_plane, plane_n, sphere_n);

        const F n_dot_d = dot(normal, d);
        // The normal facing the incoming ray; refraction uses the unflipped one.
        const V3<F> n = select(n_dot_d > zero, neg(normal), normal);
        const V3<F> w = neg(v_hat);

        // Material.
        LaneIndex mats;
        mats.uniform = ids.uniform;
        for (std::uint32_t i = 0; i < (ids.uniform ? 1 : W); ++i)
            mats.index[i] = static_cast<std::int32_t>(s.object_material[ids.index[i]]);
        V3<F> cd{gather<F>(s.mat_cd_r, mats), gather<F>(s.mat_cd_g, mats),
                 gather<F>(s.mat_cd_b, mats)};
        const F kd = gather<F>(s.mat_kd, mats), ks = gather<F>(s.mat_ks, mats);
        const F shininess = gather<F>(s.mat_shininess, mats);
        const F pow_zero = gather<F>(s.mat_pow_zero_below, mats);
        V3<F> kr{gather<F>(s.mat_kr_r, mats), gather<F>(s.mat_kr_g, mats),
                 gather<F>(s.mat_kr_b, mats)};
        const F kt = gather<F>(s.mat_kt, mats), ior = gather<F>(s.mat_ior, mats);

        // Checker (planes only): Cd2 where floor(P.T1/size) + floor(P.T2/size) is odd.
        const M checker = hit && gather<F>(s.object_checker, ids) != zero;
        if (xsimd::any(checker)) {
            const V3<F> t1{gather<F>(s.object_t1x, ids), gather<F>(s.object_t1y, ids),
                           gather<F>(s.object_t1z, ids)};
            const V3<F> t2{gather<F>(s.object_t2x, ids), gather<F>(s.object_t2y, ids),
                           gather<F>(s.object_t2z, ids)};
            const F size = gather<F>(s.mat_checker_size, mats);
            const F parity = floor_parity(dot(p, t1) / size) + floor_parity(dot(p, t2) / size);
            const V3<F> cd2{gather<F>(s.mat_checker_r, mats), gather<F>(s.mat_checker_g, mats),
                            gather<F>(s.mat_checker_b, mats)};
            cd = select(checker && parity == one, cd2, cd);
        }

        // Ambient term: ambient * (Cd * kd).
        const V3<F> color = hadamard(broadcast<F>(s.ambient), mul(cd, kd));

        // Direct light: one shadow ray per light in front of the surface; its term is
        // added to the parent's color when the shadow ray reaches the light.
        const V3<F> shadow_origin = add(p, mul(n, eps));
        for (std::uint32_t li = 0; li < s.light_count; ++li) {
            V3<F> l, shadow_dir;
            F dist2 = one;
            float shadow_t_max;
            if (s.light_directional[li] == 0) {
                const V3<F> to_light =
                    sub(V3<F>{F(s.light_px[li]), F(s.light_py[li]), F(s.light_pz[li])}, p);
                dist2 = dot(to_light, to_light);
                l = normalize(to_light);
                shadow_dir = to_light;  // not normalised: the light sits at t = 1
                shadow_t_max = 1.0f;
            } else {
                l = V3<F>{F(s.light_lx[li]), F(s.light_ly[li]), F(s.light_lz[li])};
                shadow_dir = l;
                shadow_t_max = kInf;
            }
            const F n_dot_l = dot(n, l);
            const M lit = hit && n_dot_l > zero;
            if (xsimd::none(lit)) continue;

            V3<F> radiance{F(s.light_r[li]), F(s.light_g[li]), F(s.light_b[li])};
            if (s.light_inverse_square[li] != 0) radiance = div(radiance, dist2);
            // R_l = 2(N.l)N - l; highlight = ks * max(0, R.W)^n (std::max(0, x) keeps 0
            // unless 0 < x).
            const V3<F> r = sub(mul(n, F(2.0f) * n_dot_l), l);
            const F r_dot_w = dot(r, w);
            const F clamped = xsimd::select(zero < r_dot_w, r_dot_w, zero);
            // powf per lane, only where it can be non-zero: lit, ks != 0 and the base above
            // the material's pow_zero_below (where powf itself returns 0; scene/compile.h).
            const M needs_pow = lit && ks != zero && clamped > pow_zero;
            F h = zero;
            if (const std::uint32_t pow_bits = mask_bits<F>(needs_pow); pow_bits != 0) {
                alignas(64) float highlight[W] = {}, base_pow[W], exps[W], kss[W];
                clamped.store_aligned(base_pow);
                shininess.store_aligned(exps);
                ks.store_aligned(kss);
                for (std::uint32_t i = 0; i < W; ++i)
                    if ((pow_bits >> i) & 1u)
                        highlight[i] = kss[i] * powf(base_pow[i], exps[i]);
                h = F::load_aligned(highlight);
            }
            // radiance * (Cd * (kd * N.l) + highlight)
            const V3<F> term = hadamard(radiance, add(mul(cd, kd * n_dot_l), V3<F>{h, h, h}));

            // Compact the lit lanes into the shadow stream.
            const ShadowStream& sh = out.shadows;
            const Compaction<F> lit_lanes = compaction<F>(lit);
            const std::uint32_t at = counts.shadow;
            store_compacted(lit_lanes, shadow_origin, sh.ox, sh.oy, sh.oz, at);
            store_compacted(lit_lanes, shadow_dir, sh.dx, sh.dy, sh.dz, at);
            store_compacted(lit_lanes, term, sh.term_r, sh.term_g, sh.term_b, at);
            store_count(lit_lanes, shadow_t_max, sh.t_max + at);
            store_compacted_slots(lit_lanes, base, 1, 0, sh.parent + at);
            counts.shadow += lit_lanes.count;
        }

        // Refraction first (Snell with the unflipped normal: entering when V.N < 0); total
        // internal reflection moves kt onto the mirror ray.
        // Most packets hold no glass: skip the whole block then.
        const M has_refraction = hit && kt > zero;
        M refracts = has_refraction;  // all false unless some lane refracts
        V3<F> refracted{zero, zero, zero};
        if (xsimd::any(has_refraction)) {
            const F cos_i = dot(v_hat, normal);
            const M entering = cos_i < zero;
            const F eta = xsimd::select(entering, one / ior, ior);
            const V3<F> nt = select(entering, normal, neg(normal));
            const F c = xsimd::select(entering, -cos_i, cos_i);
            const F k = one - eta * eta * (one - c * c);
            const M tir = has_refraction && k < zero;
            kr = select(tir, add(kr, V3<F>{kt, kt, kt}), kr);
            refracts = has_refraction && !(k < zero);
            refracted = add(mul(v_hat, eta), mul(nt, eta * c - xsimd::sqrt(k)));
        }

        // Mirror ray: R = V - 2(N.V)N with the unflipped normal.
        const M reflects = hit && max_component(kr) > zero;
        const V3<F> reflected = sub(d, mul(normal, F(2.0f) * n_dot_d));

        // Secondary rays within max_depth and heavy enough are traced; the others see the
        // background along their direction, scaled by their factor.
        const F min_weight(kMinRayWeight);
        const V3<F> weight_r = hadamard(weight, kr);
        const V3<F> weight_t = mul(weight, kt);
        M trace_r = reflects && max_component(weight_r) >= min_weight;
        M trace_t = refracts && max_component(weight_t) >= min_weight;
        if (!children_within_depth) trace_r = trace_t = (zero != zero);
        const M cut_r = reflects && !trace_r, cut_t = refracts && !trace_t;
        V3<F> tail_r{zero, zero, zero}, tail_t{zero, zero, zero};
        if (xsimd::any(cut_r))
            tail_r = select(cut_r, hadamard(kr, background(s, reflected)), tail_r);
        if (xsimd::any(cut_t))
            tail_t = select(cut_t, mul(background(s, refracted), kt), tail_t);

        store3(select(hit, color, sky), sc.local_r, sc.local_g, sc.local_b, base);
        store3(tail_r, sc.tail_reflect_r, sc.tail_reflect_g, sc.tail_reflect_b, base);
        store3(tail_t, sc.tail_refract_r, sc.tail_refract_g, sc.tail_refract_b, base);

        // Compact the traced children into the next generation: the mirror rays of the
        // packet, then its refracted rays. Their order does not matter: each child carries
        // its parent's slot (and which tail it fills), and render/ resolves colors through
        // these links, never through stream positions.
        if (xsimd::none(trace_r || trace_t)) continue;
        const RayStream& nx = out.next;
        const ChildLinks& links = out.next_links;
        if (xsimd::any(trace_r)) {
            const Compaction<F> lanes_r = compaction<F>(trace_r);
            const std::uint32_t at = counts.next;
            store_compacted(lanes_r, shadow_origin, nx.ox, nx.oy, nx.oz, at);
            store_compacted(lanes_r, reflected, nx.dx, nx.dy, nx.dz, at);
            store_compacted(lanes_r, weight_r, nx.wr, nx.wg, nx.wb, at);
            store_compacted(lanes_r, kr, links.factor_r, links.factor_g, links.factor_b, at);
            store_compacted_slots(lanes_r, base, 2, 0, links.parent + at);
            counts.next += lanes_r.count;
            counts.reflected += lanes_r.count;
        }
        if (xsimd::any(trace_t)) {
            const Compaction<F> lanes_t = compaction<F>(trace_t);
            const std::uint32_t at = counts.next;
            store_compacted(lanes_t, sub(p, mul(n, eps)), nx.ox, nx.oy, nx.oz, at);
            store_compacted(lanes_t, refracted, nx.dx, nx.dy, nx.dz, at);
            store_compacted(lanes_t, weight_t, nx.wr, nx.wg, nx.wb, at);
            store_compacted(lanes_t, V3<F>{kt, kt, kt}, links.factor_r, links.factor_g,
                            links.factor_b, at);
            store_compacted_slots(lanes_t, base, 2, 1, links.parent + at);
            counts.next += lanes_t.count;
            counts.refracted += lanes_t.count;
        }
    }
    return counts;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
