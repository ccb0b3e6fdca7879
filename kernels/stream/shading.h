#pragma once
// The shade entry point of the kernel table and the background it shows misses.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <math.h>

#include <cstdint>

#include "kernels/packet_math.h"
#include "kernels/stream/compaction.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// A new ray whose weight is below this in every channel is not traced (reference:
// kMinRayWeight).
constexpr float kMinRayWeight = 1e-3f;

// Parity of floor(x) as 0 or 1 (reference: floor_parity): f - 2 floor(f / 2).
template <class F>
F floor_parity(const F& x) {
    const F f = xsimd::floor(x);
    return f - F(2.0f) * xsimd::floor(f * F(0.5f));
}

// Background along a direction already normalised (reference: ReferenceTracer::background,
// which normalises first).
template <class F>
V3<F> background_unit(const SceneView& s, const V3<F>& unit) {
    if (s.background == BackgroundKind::constant) return broadcast<F>(s.bg_color);
    const F t = F(0.5f) * (dot(unit, broadcast<F>(s.bg_up)) + F(1.0f));
    const V3<F> bottom = broadcast<F>(s.bg_bottom), top = broadcast<F>(s.bg_top);
    // mix(a, b, t) = a + (b - a) * t
    return add(bottom, mul(sub(top, bottom), t));
}

// Background along a direction (reference: ReferenceTracer::background).
template <class F>
V3<F> background(const SceneView& s, const V3<F>& direction) {
    if (s.background == BackgroundKind::constant) return broadcast<F>(s.bg_color);
    return background_unit(s, normalize(direction));
}

// Shading (reference: ReferenceTracer::shade and trace's miss branch). Per ray of the
// generation: the ambient term (or the background on a miss), one shadow ray per light in
// front of the surface carrying that light's term, the mirror and refracted rays that are
// traced, and the factor * background tails of those cut off by depth or weight.
// shade_packet shades the rays [base, base + F::size) of the generation into `counts`.
template <class Arch>
[[gnu::always_inline]] inline void shade_packet(const SceneView& s, const ShadeInput& in,
                                                const ShadeOutput& out, std::uint32_t base,
                                                ShadeCounts& counts) {
    using F = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const F zero(0.0f), one(1.0f), eps(s.epsilon);
    const bool children_within_depth = in.depth + 1 <= s.max_depth;
    const RayStream& rays = in.rays;
    const SurfaceColor& sc = out.color;
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
    LaneIndex ids, records;  // records: where each lane's object record starts, in floats
    xsimd::to_int(id).store_aligned(ids.index);
    ids.uniform = xsimd::all(id == F(static_cast<float>(ids.index[0])));
    (xsimd::to_int(id) * static_cast<std::int32_t>(kObjectRecordFloats))
        .store_aligned(records.index);
    records.uniform = ids.uniform;
    const V3<F> o = load3<F>(rays.ox, rays.oy, rays.oz, base);
    const V3<F> d = load3<F>(rays.dx, rays.dy, rays.dz, base);
    const V3<F> weight = load3<F>(rays.wr, rays.wg, rays.wb, base);
    if (xsimd::none(hit)) {
        store3(background(s, d), sc.local_r, sc.local_g, sc.local_b, base);
        store3(V3<F>{zero, zero, zero}, sc.tail_reflect_r, sc.tail_reflect_g, sc.tail_reflect_b,
               base);
        store3(V3<F>{zero, zero, zero}, sc.tail_refract_r, sc.tail_refract_g, sc.tail_refract_b,
               base);
        return;
    }

    // The ray's unit direction: the shading's V^, and what a missing lane sees along it
    // (not needed when every lane hit); normalised once for both.
    const V3<F> v_hat = normalize(d);
    const V3<F> sky = all_hit ? V3<F>{zero, zero, zero} : background_unit(s, v_hat);

    // Hit point and geometric normal (reference: ReferenceTracer::intersect): sphere
    // normalize(P - c), or -V^ for a hit at the very center; plane N.
    const F t = F::load_aligned(in.hits.t + base);
    const V3<F> p = add(o, mul(d, t));
    // The object's record (scene/object_record.h).
    const float* record = s.object_record;
    const F kind = gather<F>(record + kRecordKind, records);
    const M is_plane = kind != F(kKindSphere);
    // A sphere's center and a plane's normal, each gathered only where a lane needs it:
    // a packet of spheres alone (random:N, sphereflakes) skips the normals' three gathers,
    // and one of planes alone (a floor) the centers'. The other kind's lanes stay zero,
    // which the select below never picks.
    V3<F> center{zero, zero, zero}, plane_n{zero, zero, zero};
    if (!xsimd::all(is_plane))
        center = {gather<F>(record + kRecordCx, records),
                  gather<F>(record + kRecordCy, records),
                  gather<F>(record + kRecordCz, records)};
    if (xsimd::any(is_plane))
        plane_n = {gather<F>(record + kRecordNx, records),
                   gather<F>(record + kRecordNy, records),
                   gather<F>(record + kRecordNz, records)};
    const V3<F> pc = sub(p, center);
    const V3<F> sphere_n = select(dot(pc, pc) > zero, normalize(pc), neg(v_hat));
    const V3<F> normal = select(is_plane, plane_n, sphere_n);

    const F n_dot_d = dot(normal, d);
    // The normal facing the incoming ray; refraction uses the unflipped one.
    const V3<F> n = select(n_dot_d > zero, neg(normal), normal);
    const V3<F> w = neg(v_hat);

    // Material. The material's index travels as a float's bits: gathered as floats,
    // reinterpreted. Where every lane has the same material (one object, or a scene whose
    // objects share one, as random:N's do), its fields are loaded once and broadcast
    // instead of gathered: random:1024's shading took a quarter less time.
    LaneIndex mats;
    const I material = xsimd::bitwise_cast<I>(gather<F>(record + kRecordMaterial, records));
    material.store_aligned(mats.index);
    mats.uniform = ids.uniform || xsimd::all(material == I(mats.index[0]));
    V3<F> cd{gather<F>(s.mat_cd_r, mats), gather<F>(s.mat_cd_g, mats),
             gather<F>(s.mat_cd_b, mats)};
    const F kd = gather<F>(s.mat_kd, mats), ks = gather<F>(s.mat_ks, mats);
    const F shininess = gather<F>(s.mat_shininess, mats);
    const F pow_zero = gather<F>(s.mat_pow_zero_below, mats);
    V3<F> kr{gather<F>(s.mat_kr_r, mats), gather<F>(s.mat_kr_g, mats),
             gather<F>(s.mat_kr_b, mats)};
    const F kt = gather<F>(s.mat_kt, mats), ior = gather<F>(s.mat_ior, mats);

    // Checker (planes only): Cd2 where floor(P.T1/size) + floor(P.T2/size) is odd.
    const M checker = hit && kind == F(kKindCheckerPlane);
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
                if ((pow_bits >> i) & 1u) highlight[i] = kss[i] * powf(base_pow[i], exps[i]);
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
    if (xsimd::any(cut_t)) tail_t = select(cut_t, mul(background(s, refracted), kt), tail_t);

    store3(select(hit, color, sky), sc.local_r, sc.local_g, sc.local_b, base);
    store3(tail_r, sc.tail_reflect_r, sc.tail_reflect_g, sc.tail_reflect_b, base);
    store3(tail_t, sc.tail_refract_r, sc.tail_refract_g, sc.tail_refract_b, base);

    // Compact the traced children into the next generation: the mirror rays of the
    // packet, then its refracted rays. Their order does not matter: each child carries
    // its parent's slot (and which tail it fills), and render/ resolves colors through
    // these links, never through stream positions.
    if (xsimd::none(trace_r || trace_t)) return;
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

// The kernel table's shade: a generation's rays a packet at a time. A translation unit that
// defines OCTRAY_SHADE_ARCH (the AVX-512 one: xsimd::avx512f) shades 16 rays per register
// while 16 of the stream's lanes remain, then its last 8-ray packet in the kernel's Arch
// (a stream's capacity is a whole number of 8-ray packets, kernel_types.h, so a 16-lane
// load must not pass the last one). Per lane the arithmetic is the same at either width.
template <class Arch>
ShadeCounts shade(const SceneView& s, const ShadeInput& in, const ShadeOutput& out) {
    ShadeCounts counts{0, 0, 0, 0};
    std::uint32_t base = 0;
#ifdef OCTRAY_SHADE_ARCH
    constexpr std::uint32_t kWide = xsimd::batch<float, OCTRAY_SHADE_ARCH>::size;
    const std::uint32_t packets_end =
        (in.count + kPacketWidth - 1) / kPacketWidth * kPacketWidth;
    for (; base + kWide <= packets_end; base += kWide)
        shade_packet<OCTRAY_SHADE_ARCH>(s, in, out, base, counts);
#endif
    for (; base < in.count; base += xsimd::batch<float, Arch>::size)
        shade_packet<Arch>(s, in, out, base, counts);
    return counts;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
