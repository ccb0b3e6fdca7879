// BVH traversal and the closest_hit / any_hit entry points of the kernel table. Included
// ONLY by the per-ISA translation units, after kernels/packet_kernels.h, under the same
// OCTRAY_KERNEL_NAMESPACE (kernels/README.md, "the ODR rule").
//
// The tree is scene/bvh.h's: 8-wide nodes with their children's boxes in SoA
// (scene/bvh_node.h), leaves of up to 8 spheres in SoA. Two traversals share it:
// - packet traversal (Wald et al. 2001, "Interactive rendering with coherent ray
//   tracing", widened to 8-wide nodes): the packet as a whole (a frustum, where its
//   directions' signs agree) is tested against all 8 children at once; the 8-ray packet is
//   then tested against each child box the frustum enters, lanes whose current closest hit
//   lies before the box are culled, and children are visited nearest first;
// - single-ray traversal (Wald et al. 2008, "Getting rid of packets"; embree's BVH8): one
//   ray against all 8 child boxes in one operation, near/far planes picked by the ray's
//   direction signs (Williams et al. 2005), children visited nearest first.
// A packet whose live lanes drop below SceneView::bvh_packet_min_lanes goes on ray by ray
// from that node (embree's hybrid traversal).
//
// Bit-exactness. Leaves test spheres with the brute-force kernels' exact arithmetic (same
// operands, same order), and a hit replaces the current one when it is nearer or equally
// near with a lower file index: the brute-force result (the first listed object wins a
// tie) whatever the visiting order. Box tests only decide which spheres are tested, so
// they must never cull a sphere the brute-force test would report. That test rounds. With
// u = 2^-24, the robust form (sphere_quadratic) computes l = O' - (b/a)V to within ~9u|O'|,
// so a lane with disc >= 0 has its ray pass within r + 10u|O'| of the center, and the
// roots q/a, c'/q put the point within a few u|O'| of that ray's chord (c'/q loses digits
// only for an origin within ~1e-4 r of the surface moving tangentially, where both true
// roots are ~0 and the origin lies in the box anyway). So every box is widened, per ray, by
//   32u D + 64u(D + max|O|)
// where D is the distance from the ray origin to the farthest corner of the root box
// (bounding |O'| for every sphere): the first term the sphere test's rounding, with room
// to spare, the second the rounding of the slab test itself (FMA: it decides visits, not
// values) and of O - c. (The textbook form used before was far worse: a fuzzy sphere of
// radius ~sqrt(19u)|O'| around a tiny sphere far away, and a widening of
// sqrt(r_min^2 + 32u(D^2 + r_max^2)) - r_min, up to half a radius on random:1048576.)
// The tests (tests/kernels/bvh_test.cpp) check hit for hit against brute force
// on degenerate scenes (radii from 1e-6 to 1e3, coincident spheres, spheres far apart).

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

// Needs kernels/packet_kernels.h (included just before, by the same translation unit).

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Entries of a traversal stack: a node pushes at most 8 children, and the builder keeps
// the tree below 48 + 28 levels (scene/bvh.cpp, kMaxSahDepth).
constexpr std::uint32_t kBvhStackSize = 1024;
// 32u and 64u of the margin above.
constexpr float kBvhFuzz = 0x1.0p-19f;
constexpr float kBvhSlack = 0x1.0p-18f;
// Direction components smaller than this are replaced by it (with their sign) before the
// reciprocal, so that box tests never compute 0 * inf.
constexpr float kBvhTinyDirection = 1e-18f;

// One packet's rays as the traversal reads them, lane by lane in memory: the single-ray
// traversal picks its lane's scalars from here.
struct BvhPacket {
    alignas(64) float ox[kPacketWidth], oy[kPacketWidth], oz[kPacketWidth];
    alignas(64) float dx[kPacketWidth], dy[kPacketWidth], dz[kPacketWidth];
    alignas(64) float a[kPacketWidth];  // V·V, as the sphere test computes it
    alignas(64) float inv_x[kPacketWidth], inv_y[kPacketWidth], inv_z[kPacketWidth];
    // (O + margin) * inv and (O - margin) * inv: a widened slab [min - m, max + m] is
    // entered at min * inv - lo_off (positive direction) or max * inv - hi_off (negative).
    alignas(64) float lo_off_x[kPacketWidth], lo_off_y[kPacketWidth], lo_off_z[kPacketWidth];
    alignas(64) float hi_off_x[kPacketWidth], hi_off_y[kPacketWidth], hi_off_z[kPacketWidth];
    // Closest hit: the nearest hit so far (t, file index). Any hit: t_max.
    alignas(64) float best_t[kPacketWidth], best_id[kPacketWidth];
};

struct BvhStacks {
    std::uint32_t packet_node[kBvhStackSize];
    std::uint8_t packet_mask[kBvhStackSize];
    std::uint32_t ray_node[kBvhStackSize];
};

// The widening of every box for rays from `o` (the margin derived above).
template <class F>
F bvh_margin(const SceneView& s, const V3<F>& o) {
    const auto far_extent = [](const F& x, float lo, float hi) {
        return xsimd::max(xsimd::abs(x - F(lo)), xsimd::abs(x - F(hi)));
    };
    const F ex = far_extent(o.x, s.bvh_lo[0], s.bvh_hi[0]);
    const F ey = far_extent(o.y, s.bvh_lo[1], s.bvh_hi[1]);
    const F ez = far_extent(o.z, s.bvh_lo[2], s.bvh_hi[2]);
    const F d = xsimd::sqrt(ex * ex + ey * ey + ez * ez);
    const F o_max = xsimd::max(xsimd::max(xsimd::abs(o.x), xsimd::abs(o.y)), xsimd::abs(o.z));
    const F m = F(kBvhFuzz) * d + F(kBvhSlack) * (d + o_max);
    return m * F(1.0f + 0x1.0p-10f);  // the rounding of this very computation
}

template <class F>
F safe_reciprocal(const F& d) {
    const F tiny(kBvhTinyDirection);
    return F(1.0f) / xsimd::select(xsimd::abs(d) < tiny, xsimd::copysign(tiny, d), d);
}

// Box tests stay finite while (|O| + margin + |box|) * |1/V| does; beyond this (scenes with
// coordinates past ~1e19, or an overflowing margin) a packet falls back to brute force.
constexpr float kBvhFiniteLimit = 1e37f;

// Loads a packet's rays into `p`; best_t starts at `t_far` (+inf or t_max), best_id at -1.
// Returns the lanes whose box tests stay finite (kBvhFiniteLimit).
template <class F>
std::uint32_t load_bvh_packet(const SceneView& s, const float* ox, const float* oy,
                              const float* oz, const float* dx, const float* dy,
                              const float* dz, const float* t_far, std::uint32_t base,
                              BvhPacket& p) {
    constexpr std::uint32_t W = F::size;
    float box_max = 0.0f;  // no fmaxf: it is a libm call, not an instruction
    for (int a = 0; a < 3; ++a) {
        const float lo = fabsf(s.bvh_lo[a]), hi = fabsf(s.bvh_hi[a]);
        box_max = box_max > lo ? box_max : lo;
        box_max = box_max > hi ? box_max : hi;
    }
    std::uint32_t finite = 0;
    for (std::uint32_t at = 0; at < kPacketWidth; at += W) {
        const V3<F> o = load3<F>(ox, oy, oz, base + at);
        const V3<F> d = load3<F>(dx, dy, dz, base + at);
        store3(o, p.ox, p.oy, p.oz, at);
        store3(d, p.dx, p.dy, p.dz, at);
        dot(d, d).store_aligned(p.a + at);
        const V3<F> inv{safe_reciprocal(d.x), safe_reciprocal(d.y), safe_reciprocal(d.z)};
        store3(inv, p.inv_x, p.inv_y, p.inv_z, at);
        const F m = bvh_margin(s, o);
        const F o_max =
            xsimd::max(xsimd::max(xsimd::abs(o.x), xsimd::abs(o.y)), xsimd::abs(o.z));
        const F inv_max =
            xsimd::max(xsimd::max(xsimd::abs(inv.x), xsimd::abs(inv.y)), xsimd::abs(inv.z));
        finite |= mask_bits<F>((o_max + m + F(box_max)) * inv_max < F(kBvhFiniteLimit)) << at;
        const V3<F> lo{o.x + m, o.y + m, o.z + m}, hi{o.x - m, o.y - m, o.z - m};
        store3(hadamard(lo, inv), p.lo_off_x, p.lo_off_y, p.lo_off_z, at);
        store3(hadamard(hi, inv), p.hi_off_x, p.hi_off_y, p.hi_off_z, at);
        (t_far ? F::load_aligned(t_far + base + at) : F(kInf)).store_aligned(p.best_t + at);
        F(-1.0f).store_aligned(p.best_id + at);
    }
    return finite;
}

inline std::uint32_t leaf_first(std::uint32_t ref) {
    return (ref & ~kBvhLeafBit) >> kBvhLeafCountBits;
}
inline std::uint32_t leaf_count(std::uint32_t ref) {
    return (ref & ((1u << kBvhLeafCountBits) - 1u)) + 1u;
}

// Starts loading a leaf's spheres (the first cache line of each of the four arrays). A
// packet pops the leaves it pushes soon after; without this, in a large scene, the first
// load of each array waits for memory (docs/performance-log.md, "Packets from one origin; leaf
// prefetches").
inline void prefetch_leaf(const SceneView& s, std::uint32_t ref) {
    const std::uint32_t first = leaf_first(ref);
    for (const float* a : {s.bvh_cx, s.bvh_cy, s.bvh_cz, s.bvh_r2})
        _mm_prefetch(reinterpret_cast<const char*>(a + first), _MM_HINT_T0);
}

// ---------------------------------------------------------------------------------------
// Single ray: one ray against the 8 children of a node at once.

// The ray of one lane, with its near and far planes chosen by its direction's signs.
template <class F>
struct BvhRay {
    using Plane = const float (BvhNode8::*)[kBvhWidth];
    Plane near_x, near_y, near_z, far_x, far_y, far_z;
    F inv_x, inv_y, inv_z;
    F near_off_x, near_off_y, near_off_z, far_off_x, far_off_y, far_off_z;
    V3<F> o, d;
    F a;

    BvhRay(const BvhPacket& p, std::uint32_t lane) {
        const auto axis = [&](float inv, float lo_off, float hi_off, Plane& near, Plane& far,
                              F& near_off, F& far_off, Plane min, Plane max) {
            // Positive direction: enter through min - m, leave through max + m.
            const bool positive = inv >= 0.0f;
            near = positive ? min : max;
            far = positive ? max : min;
            near_off = F(positive ? lo_off : hi_off);
            far_off = F(positive ? hi_off : lo_off);
        };
        axis(p.inv_x[lane], p.lo_off_x[lane], p.hi_off_x[lane], near_x, far_x, near_off_x,
             far_off_x, &BvhNode8::min_x, &BvhNode8::max_x);
        axis(p.inv_y[lane], p.lo_off_y[lane], p.hi_off_y[lane], near_y, far_y, near_off_y,
             far_off_y, &BvhNode8::min_y, &BvhNode8::max_y);
        axis(p.inv_z[lane], p.lo_off_z[lane], p.hi_off_z[lane], near_z, far_z, near_off_z,
             far_off_z, &BvhNode8::min_z, &BvhNode8::max_z);
        inv_x = F(p.inv_x[lane]), inv_y = F(p.inv_y[lane]), inv_z = F(p.inv_z[lane]);
        o = {F(p.ox[lane]), F(p.oy[lane]), F(p.oz[lane])};
        d = {F(p.dx[lane]), F(p.dy[lane]), F(p.dz[lane])};
        a = F(p.a[lane]);
    }

    // Bit i set when child i's widened box meets the ray on [t_near, t_far]; entry[i] is
    // where the ray enters it (unless entry is null: any hit needs no order).
    std::uint32_t test(const BvhNode8& n, const F& t_near, const F& t_far, float* entry) const {
        constexpr std::uint32_t W = F::size;
        std::uint32_t bits = 0;
        for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
            const F tnx = xsimd::fms(F::load_aligned((n.*near_x) + at), inv_x, near_off_x);
            const F tny = xsimd::fms(F::load_aligned((n.*near_y) + at), inv_y, near_off_y);
            const F tnz = xsimd::fms(F::load_aligned((n.*near_z) + at), inv_z, near_off_z);
            const F tfx = xsimd::fms(F::load_aligned((n.*far_x) + at), inv_x, far_off_x);
            const F tfy = xsimd::fms(F::load_aligned((n.*far_y) + at), inv_y, far_off_y);
            const F tfz = xsimd::fms(F::load_aligned((n.*far_z) + at), inv_z, far_off_z);
            const F tn = xsimd::max(xsimd::max(tnx, tny), xsimd::max(tnz, t_near));
            const F tf = xsimd::min(xsimd::min(tfx, tfy), xsimd::min(tfz, t_far));
            bits |= mask_bits<F>(tn <= tf) << at;
            if (entry != nullptr) tn.store_aligned(entry + at);
        }
        return bits;
    }
};

// A ray against spheres i ... i + W - 1 of a leaf (lanes at ... of its `count`): the
// brute-force arithmetic of packet_kernels.h (sphere_quadratic, sphere_roots), so the BVH
// finds the same t as brute force. `live`: lanes holding a sphere with real roots.
template <class F>
struct LeafRoots {
    typename F::batch_bool_type live;
    F t_near, t_far;
};

template <class F>
LeafRoots<F> leaf_roots(const SceneView& s, const BvhRay<F>& ray, std::uint32_t i,
                        std::uint32_t at, std::uint32_t count) {
    const F zero(0.0f);
    const V3<F> c{F::load_unaligned(s.bvh_cx + i), F::load_unaligned(s.bvh_cy + i),
                  F::load_unaligned(s.bvh_cz + i)};
    const SphereQuadratic<F> quad =
        sphere_quadratic(sub(ray.o, c), ray.d, ray.a, F::load_unaligned(s.bvh_r2 + i));
    const auto live = live_lanes<F>(at, count) && quad.disc >= zero;
    if (xsimd::none(live)) return {live, zero, zero};
    const SphereRoots<F> roots = sphere_roots(quad, ray.a);
    return {live, roots.t_near, roots.t_far};
}

// Children of `n` in `bits`, nearest first by `entry`: the nearest is returned, the rest
// pushed farthest first.
inline std::uint32_t push_children(const BvhNode8& n, std::uint32_t bits, const float* entry,
                                   std::uint32_t* stack, std::uint32_t& sp) {
    std::uint32_t order[kBvhWidth];
    std::uint32_t count = 0;
    while (bits != 0) {
        const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
        bits &= bits - 1;
        std::uint32_t k = count++;
        for (; k > 0 && entry[order[k - 1]] < entry[j]; --k) order[k] = order[k - 1];
        order[k] = j;  // descending entry
    }
    for (std::uint32_t k = 0; k + 1 < count; ++k) stack[sp++] = n.child[order[k]];
    return n.child[order[count - 1]];
}

// Children of `n` in `bits` in the node's order (the builder's: largest box first, the
// likeliest to occlude): the first is returned, the rest pushed last first.
inline std::uint32_t push_children_in_order(const BvhNode8& n, std::uint32_t bits,
                                            std::uint32_t* stack, std::uint32_t& sp) {
    const auto first = static_cast<std::uint32_t>(__builtin_ctz(bits));
    for (bits &= bits - 1; bits != 0; bits &= ~(1u << (31 - __builtin_clz(bits))))
        stack[sp++] = n.child[31 - __builtin_clz(bits)];
    return n.child[first];
}

// Closest hit of lane `lane` of `p` in the subtree `start`, on (t_min, best_t].
template <class Arch>
void bvh_closest_ray(const SceneView& s, BvhPacket& p, std::uint32_t lane, std::uint32_t start,
                     float t_min, std::uint32_t* stack) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const BvhRay<F> ray(p, lane);
    const F tmin(t_min), zero(0.0f);
    float& best_t = p.best_t[lane];
    float& best_id = p.best_id[lane];
    alignas(64) float entry[kBvhWidth];
    std::uint32_t sp = 0, node = start;
    for (;;) {
        if ((node & kBvhLeafBit) == 0) {
            const BvhNode8& n = s.bvh_nodes[node];
            const std::uint32_t bits = ray.test(n, tmin, F(best_t), entry);
            if (bits != 0) {
                node = push_children(n, bits, entry, stack, sp);
                continue;
            }
        } else {
            // Up to 8 spheres against the ray, the brute-force arithmetic per lane.
            const std::uint32_t first = leaf_first(node), count = leaf_count(node);
            for (std::uint32_t at = 0; at < count; at += W) {
                const std::uint32_t i = first + at;
                const LeafRoots<F> r = leaf_roots(s, ray, i, at, count);
                if (xsimd::none(r.live)) continue;
                const auto& live = r.live;
                const F& t_near = r.t_near;
                const F& t_far = r.t_far;
                // The sphere's candidate is its first root above t_min.
                const F t = xsimd::select(t_near > tmin, t_near, t_far);
                std::uint32_t bits = mask_bits<F>(live && t > tmin && t <= F(best_t));
                if (bits == 0) continue;
                alignas(64) float ts[W];
                t.store_aligned(ts);
                for (; bits != 0; bits &= bits - 1) {
                    const auto l = static_cast<std::uint32_t>(__builtin_ctz(bits));
                    const auto id = static_cast<float>(s.bvh_object[i + l]);
                    if (ts[l] < best_t || (ts[l] == best_t && id < best_id))
                        best_t = ts[l], best_id = id;
                }
            }
        }
        if (sp == 0) return;
        node = stack[--sp];
    }
}

// Whether lane `lane` of `p` hits a sphere of the subtree `start` on (0, t_max).
template <class Arch>
bool bvh_occluded_ray(const SceneView& s, const BvhPacket& p, std::uint32_t lane,
                      std::uint32_t start, std::uint32_t* stack) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const BvhRay<F> ray(p, lane);
    const F zero(0.0f), t_max(p.best_t[lane]);
    std::uint32_t sp = 0, node = start;
    for (;;) {
        if ((node & kBvhLeafBit) == 0) {
            const BvhNode8& n = s.bvh_nodes[node];
            const std::uint32_t bits = ray.test(n, zero, t_max, nullptr);
            if (bits != 0) {
                node = push_children_in_order(n, bits, stack, sp);
                continue;
            }
        } else {
            const std::uint32_t first = leaf_first(node), count = leaf_count(node);
            for (std::uint32_t at = 0; at < count; at += W) {
                const std::uint32_t i = first + at;
                const LeafRoots<F> r = leaf_roots(s, ray, i, at, count);
                if (xsimd::none(r.live)) continue;
                const auto& live = r.live;
                const F& t_near = r.t_near;
                const F& t_far = r.t_far;
                if (xsimd::any(live && ((t_near > zero && t_near < t_max) ||
                                        (t_far > zero && t_far < t_max))))
                    return true;
            }
        }
        if (sp == 0) return false;
        node = stack[--sp];
    }
}

// ---------------------------------------------------------------------------------------
// Packets: the 8 rays against one child box at a time.

// Lanes of the packet whose widened box of child j meets the ray on [t_near, t_far[lane]].
// Always inlined: a node runs it for each of its 8 children, and as a call (which GCC
// chose) each one also paid for the call and a vzeroupper.
template <class F>
[[gnu::always_inline]] inline std::uint32_t packet_child_lanes(const BvhNode8& n,
                                                               std::uint32_t j,
                                                               const BvhPacket& p,
                                                               const F& t_near,
                                                               const float* t_far) {
    constexpr std::uint32_t W = F::size;
    const F min_x(n.min_x[j]), max_x(n.max_x[j]), min_y(n.min_y[j]), max_y(n.max_y[j]);
    const F min_z(n.min_z[j]), max_z(n.max_z[j]);
    std::uint32_t bits = 0;
    for (std::uint32_t at = 0; at < kPacketWidth; at += W) {
        const F ix = F::load_aligned(p.inv_x + at), iy = F::load_aligned(p.inv_y + at),
                iz = F::load_aligned(p.inv_z + at);
        // Either slab plane may be the near one (lanes differ in sign): sort per lane.
        const F ax = xsimd::fms(min_x, ix, F::load_aligned(p.lo_off_x + at));
        const F bx = xsimd::fms(max_x, ix, F::load_aligned(p.hi_off_x + at));
        const F ay = xsimd::fms(min_y, iy, F::load_aligned(p.lo_off_y + at));
        const F by = xsimd::fms(max_y, iy, F::load_aligned(p.hi_off_y + at));
        const F az = xsimd::fms(min_z, iz, F::load_aligned(p.lo_off_z + at));
        const F bz = xsimd::fms(max_z, iz, F::load_aligned(p.hi_off_z + at));
        const F tn = xsimd::max(xsimd::max(xsimd::min(ax, bx), xsimd::min(ay, by)),
                                xsimd::max(xsimd::min(az, bz), t_near));
        const F tf = xsimd::min(xsimd::min(xsimd::max(ax, bx), xsimd::max(ay, by)),
                                xsimd::min(xsimd::max(az, bz), F::load_aligned(t_far + at)));
        bits |= mask_bits<F>(tn <= tf) << at;
    }
    return bits;
}

// Where lane `rep` of the packet enters each of the 8 children (children in lanes): the
// order in which the packet visits them. Only an order: it decides no hit.
template <class F>
void packet_child_keys(const BvhNode8& n, const BvhPacket& p, std::uint32_t rep, float* key) {
    constexpr std::uint32_t W = F::size;
    const F ix(p.inv_x[rep]), iy(p.inv_y[rep]), iz(p.inv_z[rep]);
    const F lo_x(p.lo_off_x[rep]), lo_y(p.lo_off_y[rep]), lo_z(p.lo_off_z[rep]);
    const F hi_x(p.hi_off_x[rep]), hi_y(p.hi_off_y[rep]), hi_z(p.hi_off_z[rep]);
    for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
        const F ax = xsimd::fms(F::load_aligned(n.min_x + at), ix, lo_x);
        const F bx = xsimd::fms(F::load_aligned(n.max_x + at), ix, hi_x);
        const F ay = xsimd::fms(F::load_aligned(n.min_y + at), iy, lo_y);
        const F by = xsimd::fms(F::load_aligned(n.max_y + at), iy, hi_y);
        const F az = xsimd::fms(F::load_aligned(n.min_z + at), iz, lo_z);
        const F bz = xsimd::fms(F::load_aligned(n.max_z + at), iz, hi_z);
        const F entry =
            xsimd::max(xsimd::max(xsimd::min(ax, bx), xsimd::min(ay, by)), xsimd::min(az, bz));
        // Ranks need a total order: a NaN (never expected) sorts as the farthest.
        xsimd::select(entry == entry, entry, F(kInf)).store_aligned(key + at);
    }
}

// ---------------------------------------------------------------------------------------
// The packet as one bundle (a frustum, after embree's stream traversal): where every live
// lane's direction has one sign on each axis, all eight children of a node are tested
// against the bundle in one pass, and only the children it enters get the per-lane tests.
//
// Per lane, a child is entered on axis x at fms(near_x, inv, near_off) (near_x: the box's
// min_x for a positive direction, max_x for a negative one) and left at
// fms(far_x, inv, far_off). Over the bundle, with inv in [inv_lo, inv_hi] (one sign) and
// the offsets bounded by the lanes' largest near_off and smallest far_off, the exact value
// near_x * inv - near_off is at least min(near_x * inv_lo, near_x * inv_hi) - near_off_max,
// and rounding is monotonic: the bundle's rounded entry is never above any lane's rounded
// entry, its exit never below. A child some lane enters is entered by the bundle, so the
// bundle test culls nothing the per-lane tests would keep: the traversal and its hits
// are the same with it or without it.
//
// Where the live lanes also share their origin (a pinhole camera's packet), the bundle is
// nearly as tight as its rays: on random:1048576, per-lane tests dropped only 5 % of the
// children it entered. They then cost more than they cull, and every child the bundle
// enters takes all the packet's lanes; the bundle's own t_far (the farthest closest hit so
// far) still culls the children behind every lane's hit. Rays from many origins
// (reflections, shadows) spread the bundle's offsets and keep the per-lane tests
// (docs/performance-log.md, "Packets from one origin; leaf prefetches").
template <class F>
struct PacketFrustum {
    using Plane = const float (BvhNode8::*)[kBvhWidth];
    bool valid = false;       // every axis has one direction sign over the lanes
    bool one_origin = false;  // ... and the lanes share their origin
    Plane near[3], far[3];
    F inv_lo[3], inv_hi[3], near_off[3], far_off[3];
};

// Lanes of `bits` (of 8) as an AVX mask. AVX2 translation unit only (F::size == 8); a
// template, so that no other translation unit compiles it (the ODR rule).
template <class F>
__m256 lane_mask8(std::uint32_t bits) {
    const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), lane_bit), lane_bit));
}

// The largest / smallest of v[i] over the lanes i in `bits` (not empty). Exact: min and
// max do not round, so the order of the reduction does not matter.
template <class F>
float masked_max(const float* v, std::uint32_t bits) {
    if constexpr (F::size == 8) {
        const __m256 x =
            _mm256_blendv_ps(_mm256_set1_ps(-kInf), _mm256_load_ps(v), lane_mask8<F>(bits));
        __m128 m = _mm_max_ps(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1));
        m = _mm_max_ps(m, _mm_movehl_ps(m, m));
        return _mm_cvtss_f32(_mm_max_ss(m, _mm_shuffle_ps(m, m, 1)));
    } else {
        float m = -kInf;
        for (; bits != 0; bits &= bits - 1) {
            const float x = v[__builtin_ctz(bits)];
            m = x > m ? x : m;
        }
        return m;
    }
}
template <class F>
float masked_min(const float* v, std::uint32_t bits) {
    if constexpr (F::size == 8) {
        const __m256 x =
            _mm256_blendv_ps(_mm256_set1_ps(kInf), _mm256_load_ps(v), lane_mask8<F>(bits));
        __m128 m = _mm_min_ps(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1));
        m = _mm_min_ps(m, _mm_movehl_ps(m, m));
        return _mm_cvtss_f32(_mm_min_ss(m, _mm_shuffle_ps(m, m, 1)));
    } else {
        float m = kInf;
        for (; bits != 0; bits &= bits - 1) {
            const float x = v[__builtin_ctz(bits)];
            m = x < m ? x : m;
        }
        return m;
    }
}
// Whether v[i] == v[first lane of bits] for every lane i in `bits`.
template <class F>
bool masked_all_equal(const float* v, std::uint32_t bits) {
    const float v0 = v[__builtin_ctz(bits)];
    if constexpr (F::size == 8) {
        const __m256 eq = _mm256_cmp_ps(_mm256_load_ps(v), _mm256_set1_ps(v0), _CMP_EQ_OQ);
        const auto eq_bits = static_cast<std::uint32_t>(_mm256_movemask_ps(eq));
        return (eq_bits & bits) == bits;
    } else {
        for (; bits != 0; bits &= bits - 1)
            if (!(v[__builtin_ctz(bits)] == v0)) return false;
        return true;
    }
}

// `live`: not empty.
template <class F>
PacketFrustum<F> packet_frustum(const BvhPacket& p, std::uint32_t live) {
    using Plane = typename PacketFrustum<F>::Plane;
    const float* const inv[3] = {p.inv_x, p.inv_y, p.inv_z};
    const float* const lo_off[3] = {p.lo_off_x, p.lo_off_y, p.lo_off_z};
    const float* const hi_off[3] = {p.hi_off_x, p.hi_off_y, p.hi_off_z};
    const Plane mins[3] = {&BvhNode8::min_x, &BvhNode8::min_y, &BvhNode8::min_z};
    const Plane maxs[3] = {&BvhNode8::max_x, &BvhNode8::max_y, &BvhNode8::max_z};
    PacketFrustum<F> f;
    for (int a = 0; a < 3; ++a) {
        const float lo = masked_min<F>(inv[a], live), hi = masked_max<F>(inv[a], live);
        const bool positive = lo > 0.0f;
        if (!positive && !(hi < 0.0f)) return f;  // mixed signs (or NaN): no bundle
        const float near_max = masked_max<F>(positive ? lo_off[a] : hi_off[a], live);
        const float far_min = masked_min<F>(positive ? hi_off[a] : lo_off[a], live);
        f.near[a] = positive ? mins[a] : maxs[a];
        f.far[a] = positive ? maxs[a] : mins[a];
        f.inv_lo[a] = F(lo), f.inv_hi[a] = F(hi);
        f.near_off[a] = F(near_max), f.far_off[a] = F(far_min);
    }
    f.valid = true;
    f.one_origin = masked_all_equal<F>(p.ox, live) && masked_all_equal<F>(p.oy, live) &&
                   masked_all_equal<F>(p.oz, live);
    return f;
}

// The children of `n` that are not kBvhEmpty, as bits (they come first).
inline std::uint32_t used_children(const BvhNode8& n) {
    std::uint32_t count = 0;
    while (count < kBvhWidth && n.child[count] != kBvhEmpty) ++count;
    return (1u << count) - 1u;
}

// Children of `n` the bundle enters on [t_near, t_far]; entry[j]: where it enters child j.
template <class F>
[[gnu::always_inline]] inline std::uint32_t frustum_children(const BvhNode8& n,
                                                             const PacketFrustum<F>& f,
                                                             const F& t_near, const F& t_far,
                                                             float* entry) {
    constexpr std::uint32_t W = F::size;
    std::uint32_t bits = 0;
    for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
        F tn = t_near, tf = t_far;
        for (int a = 0; a < 3; ++a) {
            const F near = F::load_aligned((n.*f.near[a]) + at);
            const F far = F::load_aligned((n.*f.far[a]) + at);
            tn = xsimd::max(tn, xsimd::min(xsimd::fms(near, f.inv_lo[a], f.near_off[a]),
                                           xsimd::fms(near, f.inv_hi[a], f.near_off[a])));
            tf = xsimd::min(tf, xsimd::max(xsimd::fms(far, f.inv_lo[a], f.far_off[a]),
                                           xsimd::fms(far, f.inv_hi[a], f.far_off[a])));
        }
        bits |= mask_bits<F>(tn <= tf) << at;
        tn.store_aligned(entry + at);
    }
    return bits;
}

// Pushes the children of `n` that some lane of `mask` enters, nearest on top: nearest
// where the bundle enters them, or, without a bundle, along the representative lane. Only
// the children the bundle enters get the per-lane tests (none, for a bundle from one
// origin: each child takes all of `mask`); these are independent (no branch between them,
// so the CPU overlaps them), and the entered children are then placed by rank, without a
// data-dependent branch: child j goes below every entered child nearer than it (ties: the
// lower index nearer). The leaves among them start loading (prefetch_leaf).
template <class F, bool kNearestFirst = true>
void push_packet_children(const SceneView& s, const BvhNode8& n, const BvhPacket& p,
                          const PacketFrustum<F>& fr, std::uint32_t mask, const F& t_near,
                          const float* t_far, BvhStacks& st, std::uint32_t& sp) {
    constexpr std::uint32_t W = F::size;
    std::uint32_t lanes[kBvhWidth] = {}, entered = 0;
    alignas(64) float key[kBvhWidth];
    const std::uint32_t candidates =
        fr.valid ? frustum_children<F>(n, fr, t_near, F(masked_max<F>(t_far, mask)), key)
                 : used_children(n);
    if (fr.one_origin) {
        for (std::uint32_t j = 0; j < kBvhWidth; ++j) lanes[j] = mask;
        entered = candidates;
    } else {
        for (std::uint32_t bits = candidates; bits != 0; bits &= bits - 1) {
            const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
            lanes[j] = packet_child_lanes(n, j, p, t_near, t_far) & mask;
            entered |= static_cast<std::uint32_t>(lanes[j] != 0) << j;
        }
    }
    if (entered == 0) return;
    for (std::uint32_t bits = entered; bits != 0; bits &= bits - 1) {
        const std::uint32_t child = n.child[__builtin_ctz(bits)];
        if ((child & kBvhLeafBit) != 0) prefetch_leaf(s, child);
    }
    const auto count = static_cast<std::uint32_t>(__builtin_popcount(entered));
    if (count == 1 || !kNearestFirst) {
        // One child, or any hit (which needs no order): node order (largest box first, the
        // likeliest occluder), the first on top.
        for (std::uint32_t bits = entered, slot = sp + count; bits != 0; bits &= bits - 1) {
            const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
            st.packet_node[--slot] = n.child[j];
            st.packet_mask[slot] = static_cast<std::uint8_t>(lanes[j]);
        }
        sp += count;
        return;
    }
    if (!fr.valid)
        packet_child_keys<F>(n, p, static_cast<std::uint32_t>(__builtin_ctz(mask)), key);
    alignas(64) static constexpr float kIndex[kBvhWidth] = {0, 1, 2, 3, 4, 5, 6, 7};
    for (std::uint32_t bits = entered; bits != 0; bits &= bits - 1) {
        const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
        const F kj(key[j]), index_j(static_cast<float>(j));
        std::uint32_t nearer = 0;  // entered children that must be pushed after j
        for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
            const F k = F::load_aligned(key + at), index = F::load_aligned(kIndex + at);
            nearer |= mask_bits<F>(k < kj || (k == kj && index < index_j)) << at;
        }
        const std::uint32_t slot =
            sp + count - 1 - static_cast<std::uint32_t>(__builtin_popcount(nearer & entered));
        st.packet_node[slot] = n.child[j];
        st.packet_mask[slot] = static_cast<std::uint8_t>(lanes[j]);
    }
    sp += count;
}

// Closest hits of the packet `p` (lanes `live`, not empty: packet_frustum) among the BVH's
// spheres.
template <class Arch>
void bvh_closest_packet(const SceneView& s, BvhPacket& p, std::uint32_t live, float t_min,
                        BvhStacks& st) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kPacketWidth / W;
    const F tmin(t_min), zero(0.0f);
    const PacketFrustum<F> fr = packet_frustum<F>(p, live);
    std::uint32_t sp = 0;
    st.packet_node[sp] = 0, st.packet_mask[sp++] = static_cast<std::uint8_t>(live);
    while (sp > 0) {
        --sp;
        const std::uint32_t node = st.packet_node[sp], mask = st.packet_mask[sp];
        if (static_cast<std::uint32_t>(__builtin_popcount(mask)) < s.bvh_packet_min_lanes) {
            for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1)
                bvh_closest_ray<Arch>(s, p, static_cast<std::uint32_t>(__builtin_ctz(bits)),
                                      node, t_min, st.ray_node);
            continue;
        }
        if ((node & kBvhLeafBit) == 0) {
            push_packet_children(s, s.bvh_nodes[node], p, fr, mask, tmin, p.best_t, st, sp);
            continue;
        }
        // A leaf: each sphere broadcast against the packet, as the brute-force kernel does,
        // with ties to the lower file index.
        V3<F> o[K], d[K];
        F a[K], best_t[K], best_id[K];
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = k * W;
            o[k] = load3<F>(p.ox, p.oy, p.oz, at);
            d[k] = load3<F>(p.dx, p.dy, p.dz, at);
            a[k] = F::load_aligned(p.a + at);
            best_t[k] = F::load_aligned(p.best_t + at);
            best_id[k] = F::load_aligned(p.best_id + at);
        }
        const std::uint32_t first = leaf_first(node), end = first + leaf_count(node);
        for (std::uint32_t i = first; i < end; ++i) {
            const V3<F> c{F(s.bvh_cx[i]), F(s.bvh_cy[i]), F(s.bvh_cz[i])};
            const F r2(s.bvh_r2[i]);
            SphereQuadratic<F> quad[K];
            auto any_root = zero != zero;
            for (std::uint32_t k = 0; k < K; ++k) {
                quad[k] = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                any_root = any_root || quad[k].disc >= zero;
            }
            if (xsimd::none(any_root)) continue;
            const F id(static_cast<float>(s.bvh_object[i]));
            for (std::uint32_t k = 0; k < K; ++k) {
                const auto [t_near, t_far] = sphere_roots(quad[k], a[k]);
                const F t = xsimd::select(t_near > tmin, t_near, t_far);
                const auto hit =
                    t > tmin && (t < best_t[k] || (t == best_t[k] && id < best_id[k]));
                best_t[k] = xsimd::select(hit, t, best_t[k]);
                best_id[k] = xsimd::select(hit, id, best_id[k]);
            }
        }
        for (std::uint32_t k = 0; k < K; ++k) {
            best_t[k].store_aligned(p.best_t + k * W);
            best_id[k].store_aligned(p.best_id + k * W);
        }
    }
}

// Sets bit i of the result for each lane of `live` (not empty: packet_frustum) that a sphere
// occludes on (0, t_max).
template <class Arch>
std::uint32_t bvh_occluded_packet(const SceneView& s, const BvhPacket& p, std::uint32_t live,
                                  BvhStacks& st) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kPacketWidth / W;
    const F zero(0.0f);
    const PacketFrustum<F> fr = packet_frustum<F>(p, live);
    std::uint32_t done = 0, sp = 0;
    st.packet_node[sp] = 0, st.packet_mask[sp++] = static_cast<std::uint8_t>(live);
    while (sp > 0 && done != live) {
        --sp;
        const std::uint32_t node = st.packet_node[sp], mask = st.packet_mask[sp] & ~done;
        if (mask == 0) continue;
        if (static_cast<std::uint32_t>(__builtin_popcount(mask)) < s.bvh_packet_min_lanes) {
            for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
                const auto lane = static_cast<std::uint32_t>(__builtin_ctz(bits));
                if (bvh_occluded_ray<Arch>(s, p, lane, node, st.ray_node)) done |= 1u << lane;
            }
            continue;
        }
        if ((node & kBvhLeafBit) == 0) {
            push_packet_children<F, false>(s, s.bvh_nodes[node], p, fr, mask, zero, p.best_t,
                                           st, sp);
            continue;
        }
        V3<F> o[K], d[K];
        F a[K], t_max[K];
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = k * W;
            o[k] = load3<F>(p.ox, p.oy, p.oz, at);
            d[k] = load3<F>(p.dx, p.dy, p.dz, at);
            a[k] = F::load_aligned(p.a + at);
            t_max[k] = F::load_aligned(p.best_t + at);
        }
        const std::uint32_t first = leaf_first(node), end = first + leaf_count(node);
        for (std::uint32_t i = first; i < end && (done & mask) != mask; ++i) {
            const V3<F> c{F(s.bvh_cx[i]), F(s.bvh_cy[i]), F(s.bvh_cz[i])};
            const F r2(s.bvh_r2[i]);
            for (std::uint32_t k = 0; k < K; ++k) {
                const SphereQuadratic<F> quad = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                if (xsimd::none(quad.disc >= zero)) continue;
                const auto [t_near, t_far] = sphere_roots(quad, a[k]);
                const auto hit =
                    (t_near > zero && t_near < t_max[k]) || (t_far > zero && t_far < t_max[k]);
                done |= (mask_bits<F>(hit) << (k * W)) & mask;
            }
        }
    }
    return done;
}

// Lanes [base, base + 8) below count, as bits.
inline std::uint32_t live_bits(std::uint32_t base, std::uint32_t count) {
    const std::uint32_t left = count - base;
    return left >= kPacketWidth ? (1u << kPacketWidth) - 1u : (1u << left) - 1u;
}

// ---------------------------------------------------------------------------------------
// The kernel table's entry points: the BVH when the scene view has one, else brute force.

template <class Arch>
void closest_hit(const SceneView& s, const RayStream& rays, std::uint32_t count, float t_min,
                 const HitStream& hits) {
    if (s.bvh_nodes == nullptr) return closest_hit_all<Arch>(s, rays, count, t_min, hits);
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    BvhPacket p;
    BvhStacks st;
    const F tmin(t_min);
    for (std::uint32_t base = 0; base < count; base += kPacketWidth) {
        const std::uint32_t live = live_bits(base, count);
        if ((load_bvh_packet<F>(s, rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz,
                                nullptr, base, p) &
             live) != live) {
            // Box tests would overflow: this packet against every sphere.
            const RayStream one{rays.ox + base,   rays.oy + base, rays.oz + base,
                                rays.dx + base,   rays.dy + base, rays.dz + base,
                                rays.wr + base,   rays.wg + base, rays.wb + base,
                                rays.pixel + base};
            closest_hit_all<Arch>(s, one,
                                  count - base < kPacketWidth ? count - base : kPacketWidth,
                                  t_min, HitStream{hits.t + base, hits.object + base});
            continue;
        }
        bvh_closest_packet<Arch>(s, p, live, t_min, st);
        // Planes stay outside the tree.
        for (std::uint32_t at = 0; at < kPacketWidth; at += W) {
            F best_t = F::load_aligned(p.best_t + at),
              best_id = F::load_aligned(p.best_id + at);
            closest_planes(s, load3<F>(p.ox, p.oy, p.oz, at), load3<F>(p.dx, p.dy, p.dz, at),
                           tmin, best_t, best_id);
            best_t.store_aligned(hits.t + base + at);
            xsimd::to_int(best_id).store_aligned(hits.object + base + at);  // ids < 2^24
        }
    }
}

// Whether each live lane of the 8 rays from `base` of `rays` is occluded, as bits.
template <class Arch>
std::uint32_t occluded_packet(const SceneView& s, const ShadowStream& rays, std::uint32_t base,
                              std::uint32_t live, BvhPacket& p, BvhStacks& st) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    if ((load_bvh_packet<F>(s, rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, rays.t_max,
                            base, p) &
         live) != live) {
        // Box tests would overflow: this packet against every sphere.
        const ShadowStream one{rays.ox + base,     rays.oy + base,     rays.oz + base,
                               rays.dx + base,     rays.dy + base,     rays.dz + base,
                               rays.t_max + base,  rays.term_r + base, rays.term_g + base,
                               rays.term_b + base, rays.parent + base};
        std::uint32_t flags[kPacketWidth] = {};
        any_hit_all<Arch>(s, one, static_cast<std::uint32_t>(32 - __builtin_clz(live)), flags);
        std::uint32_t bits = 0;
        for (std::uint32_t i = 0; i < kPacketWidth; ++i) bits |= (flags[i] & 1u) << i;
        return bits & live;
    }
    // Planes first: a lane they occlude needs no traversal.
    std::uint32_t done = 0;
    for (std::uint32_t at = 0; at < kPacketWidth; at += W)
        done |= mask_bits<F>(any_plane(s, load3<F>(p.ox, p.oy, p.oz, at),
                                       load3<F>(p.dx, p.dy, p.dz, at),
                                       F::load_aligned(p.best_t + at)))
                << at;
    done &= live;
    if (done == live) return done;  // no lane left to trace
    return done | bvh_occluded_packet<Arch>(s, p, live & ~done, st);
}

// Shadow rays are traced in batches of up to this many, regrouped into packets of rays
// whose origins lie close together (in BVHs of SceneView::bvh_shadow_sort_min_spheres
// spheres or more); smaller calls are traced in the order given.
constexpr std::uint32_t kShadowBatch = 4096;
constexpr std::uint32_t kShadowSortMin = 64;

// The sort keys of shadow rays [at, at + W) (lanes past the stream's end read its
// padding, and their keys go unused): each ray's direction octant (3 sign bits: rays of
// one packet then mostly share their signs, so the packet's frustum test applies), then
// the cell of the BVH's root box (32 per axis, clamped) that holds its origin, as a
// 15-bit Morton code (neighbouring cells get neighbouring codes).
template <class F>
void shadow_keys(const SceneView& s, const ShadowStream& rays, std::uint32_t at,
                 std::uint32_t* key) {
    using I = xsimd::batch<std::int32_t, typename F::arch_type>;
    const float* const o[3] = {rays.ox + at, rays.oy + at, rays.oz + at};
    const float* const d[3] = {rays.dx + at, rays.dy + at, rays.dz + at};
    I code(0);
    for (int a = 0; a < 3; ++a) {
        const float extent = s.bvh_hi[a] - s.bvh_lo[a];
        const F scale(extent > 0.0f && 32.0f / extent < kInf ? 32.0f / extent : 0.0f);
        // max(NaN, 0) is 0 (the second operand): below the box or NaN, cell 0.
        const F f = xsimd::max((F::load_unaligned(o[a]) - F(s.bvh_lo[a])) * scale, F(0.0f));
        I q = xsimd::to_int(xsimd::min(f, F(31.0f)));
        q = (q | (q << 8)) & I(0x0300F);  // 5 bits spread to every third bit
        q = (q | (q << 4)) & I(0x030C3);
        q = (q | (q << 2)) & I(0x09249);
        // The direction's sign bit.
        const I sign = (xsimd::bitwise_cast<I>(F::load_unaligned(d[a])) >> 31) & I(1);
        code = code | (q << a) | (sign << (15 + a));
    }
    code.store_unaligned(reinterpret_cast<std::int32_t*>(key));
}

template <class Arch>
void any_hit(const SceneView& s, const ShadowStream& rays, std::uint32_t count,
             std::uint32_t* occluded) {
    if (s.bvh_nodes == nullptr) return any_hit_all<Arch>(s, rays, count, occluded);
    BvhPacket p;
    BvhStacks st;
    if (count < kShadowSortMin || s.sphere_count < s.bvh_shadow_sort_min_spheres) {
        for (std::uint32_t base = 0; base < count; base += kPacketWidth) {
            const std::uint32_t live = live_bits(base, count);
            const std::uint32_t bits = occluded_packet<Arch>(s, rays, base, live, p, st);
            for (std::uint32_t i = 0; i < kPacketWidth; ++i)
                occluded[base + i] = (bits >> i) & 1u;
        }
        return;
    }
    // Packets of neighbouring pixels' shadow rays start on surfaces at any depth and may
    // head for different lights, and their traversals share little. Sorted by direction
    // octant and origin cell, rays from one neighbourhood towards one light travel
    // together (docs/performance-log.md: shadow rays 7-13 % faster on random:65536,
    // random:1048576 and sphereflake:5). Each ray's answer is exact whatever its packet,
    // so the order changes no result. The sort is a counting sort of words holding the key
    // (18 bits) above the ray's index in the batch (12 bits), two passes of 9 bits.
    static_assert(kShadowBatch <= 4096);
    alignas(64) std::uint32_t order[kShadowBatch], sorted[kShadowBatch];
    struct Gathered {
        alignas(64) float ox[kPacketWidth], oy[kPacketWidth], oz[kPacketWidth];
        alignas(64) float dx[kPacketWidth], dy[kPacketWidth], dz[kPacketWidth];
        alignas(64) float t_max[kPacketWidth], term[kPacketWidth];
        std::uint32_t parent[kPacketWidth];
    } g;
    const ShadowStream packet{g.ox,    g.oy,   g.oz,   g.dx,   g.dy,    g.dz,
                              g.t_max, g.term, g.term, g.term, g.parent};
    for (std::uint32_t first = 0; first < count; first += kShadowBatch) {
        const std::uint32_t n = count - first < kShadowBatch ? count - first : kShadowBatch;
        using F = xsimd::batch<float, Arch>;
        for (std::uint32_t i = 0; i < n; i += F::size)
            shadow_keys<F>(s, rays, first + i, order + i);
        for (std::uint32_t i = 0; i < n; ++i) order[i] = order[i] << 12 | i;
        std::uint32_t* from = order;
        std::uint32_t* to = sorted;
        for (std::uint32_t shift = 12; shift < 30; shift += 9, std::swap(from, to)) {
            std::uint32_t start[513] = {};
            for (std::uint32_t i = 0; i < n; ++i) ++start[((from[i] >> shift) & 511u) + 1];
            for (std::uint32_t k = 1; k < 513; ++k) start[k] += start[k - 1];
            for (std::uint32_t i = 0; i < n; ++i)
                to[start[(from[i] >> shift) & 511u]++] = from[i];
        }
        for (std::uint32_t i = 0; i < n; ++i) order[i] = from[i] & 4095u;  // from == order
        for (std::uint32_t k = 0; k < n; k += kPacketWidth) {
            const std::uint32_t live = live_bits(k, n);
            for (std::uint32_t l = 0; l < kPacketWidth; ++l) {
                // Dead lanes repeat the first ray: finite values, never read back.
                const std::uint32_t r = first + order[(live >> l & 1u) != 0 ? k + l : k];
                g.ox[l] = rays.ox[r], g.oy[l] = rays.oy[r], g.oz[l] = rays.oz[r];
                g.dx[l] = rays.dx[r], g.dy[l] = rays.dy[r], g.dz[l] = rays.dz[r];
                g.t_max[l] = rays.t_max[r], g.term[l] = 0.0f, g.parent[l] = 0;
            }
            const std::uint32_t bits = occluded_packet<Arch>(s, packet, 0, live, p, st);
            for (std::uint32_t l = 0; l < kPacketWidth && k + l < n; ++l)
                occluded[first + order[k + l]] = (bits >> l) & 1u;
        }
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
