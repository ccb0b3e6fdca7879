#pragma once
// The camera_rays entry point of the kernel table: film positions to primary rays.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <math.h>

#include <cstdint>

#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// 2 * std::numbers::pi_v<float>, as the reference's thin lens computes it.
constexpr float kTwoPi = 2.0f * 3.14159265358979323846f;

// Camera: film positions to primary rays (reference: ReferenceTracer::camera_ray), the
// samples [base, base + F::size) of `in`; `written` counts the rays written. A fisheye
// sample outside the image circle has no ray, so the fisheye compacts its packets, every
// other camera writes one ray per sample.
template <class Arch>
[[gnu::always_inline]] inline void camera_packet(const SceneView& s, const CameraSamples& in,
                                                 std::uint32_t count, const RayStream& out,
                                                 std::uint32_t base, std::uint32_t& written) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const V3<F> eye = broadcast<F>(s.eye), ln = broadcast<F>(s.ln);
    const V3<F> u_hat = broadcast<F>(s.u_hat), v_hat = broadcast<F>(s.v_hat);
    const V3<F> u = broadcast<F>(s.u), v = broadcast<F>(s.v);
    const F one(1.0f);
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
        store3(V3<F>{one, one, one}, out.wr, out.wg, out.wb, base);
        // The samples' pixels, 0 past the count (whole registers: the lanes are loaded
        // as floats, bit for bit, and the dead ones zeroed; a lane at or past the count
        // may hold anything the caller's padding left).
        const F pixels = F::load_aligned(reinterpret_cast<const float*>(in.pixel) + base);
        xsimd::select(live_lanes<F>(base, count), pixels, F(0.0f))
            .store_aligned(reinterpret_cast<float*>(out.pixel) + base);
        written += lanes;
        return;
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

// The kernel table's camera_rays: the samples a packet at a time; returns the number of
// rays written. A translation unit that defines OCTRAY_SHADE_ARCH (the AVX-512 one) takes
// 16 samples per register while 16 of the stream's lanes remain, then its last 8-sample
// packet in the kernel's Arch, as shade() does (kernels/stream/shading.h). Per lane the
// arithmetic is the same at either width.
template <class Arch>
std::uint32_t camera_rays(const SceneView& s, const CameraSamples& in, std::uint32_t count,
                          const RayStream& out) {
    std::uint32_t written = 0, base = 0;
#ifdef OCTRAY_SHADE_ARCH
    constexpr std::uint32_t kWide = xsimd::batch<float, OCTRAY_SHADE_ARCH>::size;
    const std::uint32_t packets_end = (count + kPacketWidth - 1) / kPacketWidth * kPacketWidth;
    for (; base + kWide <= packets_end; base += kWide)
        camera_packet<OCTRAY_SHADE_ARCH>(s, in, count, out, base, written);
#endif
    for (; base < count; base += xsimd::batch<float, Arch>::size)
        camera_packet<Arch>(s, in, count, out, base, written);
    return written;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
