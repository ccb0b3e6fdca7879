// Embree 3 baseline (compiled only when CMake finds Embree): the octray scene rebuilt as
// Embree geometry, tracing the bench's ray sets one ray at a time or in 8- and 16-wide
// packets.

#include "bench/embree_baseline.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/embree_user_spheres.h"

namespace octray::bench {

const char* embree_mode_name(EmbreeMode mode) {
    switch (mode) {
        case EmbreeMode::single:
            return "single";
        case EmbreeMode::packet8:
            return "packet8";
        case EmbreeMode::packet16:
            return "packet16";
    }
    return "?";
}

const char* embree_geometry_name(EmbreeGeometry geometry) {
    return geometry == EmbreeGeometry::user ? "user" : "sphere_point";
}

const char* embree_build_quality_name(EmbreeBuildQuality quality) {
    switch (quality) {
        case EmbreeBuildQuality::low:
            return "low";
        case EmbreeBuildQuality::medium:
            return "medium";
        case EmbreeBuildQuality::high:
            return "high";
    }
    return "?";
}

namespace {

// An infinite plane becomes one quad reaching at least this many times the scene's size
// from the point below the eye: a ray that hits the plane further out misses the quad. For
// the default scenes' camera heights, that is a ray within ~1e-6 rad of the horizon.
constexpr float kPlaneHalfSizeScale = 1e6f;

void throw_error(RTCDevice device, const char* what) {
    const RTCError code = rtcGetDeviceError(device);
    throw std::runtime_error(std::string("Embree: ") + what + " failed (error " +
                             std::to_string(static_cast<int>(code)) + ")");
}

}  // namespace

struct EmbreeScene::Impl {
    EmbreeGeometry geometry = EmbreeGeometry::user;
    EmbreeBuildQuality quality = EmbreeBuildQuality::high;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    RTCScene plane_scene = nullptr;  // user: the planes, instanced into `scene`
    EmbreeSphereData spheres{};      // user: what the sphere callbacks read
    std::atomic<std::uint64_t> sphere_builds{0};
    // Per geometry ID of `scene`: primitive ID -> object file index; a hit through the
    // planes' instance: primitive ID -> object file index.
    std::vector<std::vector<std::int32_t>> object_of;
    std::vector<std::int32_t> instanced_plane_object;
    double build_seconds = 0.0;
    std::string last_error;
    // Bytes allocated minus bytes freed through the device (memory monitor callback).
    std::atomic<std::int64_t> live_bytes{0};
    std::int64_t bytes_after_build = 0;

    // Every geometry attached, for rebuild(): its scene, handle (the scene holds a
    // reference) and how to mark it modified.
    enum class Kind { user, buffers, instance };
    struct Attached {
        RTCScene scene;
        RTCGeometry geometry;
        Kind kind;
        unsigned primitives;
    };
    std::vector<Attached> attached;

    std::int32_t object(unsigned geom_id, unsigned prim_id, unsigned inst_id) const {
        if (geom_id == RTC_INVALID_GEOMETRY_ID) return kernels::kNoHit;
        if (inst_id != RTC_INVALID_GEOMETRY_ID) return instanced_plane_object[prim_id];
        return object_of[geom_id][prim_id];
    }

    void attach(RTCScene target, RTCGeometry g, std::vector<std::int32_t> objects, Kind kind) {
        attached.push_back({target, g, kind, static_cast<unsigned>(objects.size())});
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(target, g);
        rtcReleaseGeometry(g);
        if (target != scene) {
            instanced_plane_object = std::move(objects);
            return;
        }
        if (object_of.size() <= id) object_of.resize(id + 1);
        object_of[id] = std::move(objects);
    }
};

EmbreeScene::EmbreeScene(const Scene& scene, const CompiledScene& compiled, int threads,
                         EmbreeGeometry geometry, EmbreeBuildQuality quality)
    : impl_(std::make_unique<Impl>()) {
    Impl& im = *impl_;
    im.geometry = geometry;
    im.quality = quality;
    const RTCBuildQuality build_quality =
        quality == EmbreeBuildQuality::low      ? RTC_BUILD_QUALITY_LOW
        : quality == EmbreeBuildQuality::medium ? RTC_BUILD_QUALITY_MEDIUM
                                                : RTC_BUILD_QUALITY_HIGH;
    const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
    im.device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!im.device) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtcSetDeviceErrorFunction(
        im.device,
        [](void* user, RTCError, const char* message) {
            static_cast<Impl*>(user)->last_error = message ? message : "";
        },
        &im);
    rtcSetDeviceMemoryMonitorFunction(
        im.device,
        [](void* user, ssize_t bytes, bool) {
            static_cast<Impl*>(user)->live_bytes += static_cast<std::int64_t>(bytes);
            return true;
        },
        &im);
    im.scene = rtcNewScene(im.device);
    rtcSetSceneBuildQuality(im.scene, build_quality);

    const CompiledSpheres& s = compiled.spheres;
    if (s.count > 0 && geometry == EmbreeGeometry::user) {
        // Spheres: one user geometry, a primitive per sphere (the compiled order), boxes
        // c -+ r widened by a few ulps so that rounding never clips a sphere.
        RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_USER);
        if (!g) throw_error(im.device, "rtcNewGeometry(USER)");
        im.spheres = {s.cx.data(), s.cy.data(), s.cz.data(), s.r2.data(), &im.sphere_builds};
        rtcSetGeometryUserPrimitiveCount(g, s.count);
        rtcSetGeometryUserData(g, &im.spheres);
        rtcSetGeometryBoundsFunction(
            g,
            [](const RTCBoundsFunctionArguments* args) {
                const auto& d = *static_cast<const EmbreeSphereData*>(args->geometryUserPtr);
                const unsigned i = args->primID;
                if (i == 0) d.builds->fetch_add(1, std::memory_order_relaxed);
                const float r = std::sqrt(d.r2[i]) * (1.0f + 0x1.0p-20f);
                const auto lo = [r](float c) { return (c - r) - std::fabs(c) * 0x1.0p-22f; };
                const auto hi = [r](float c) { return (c + r) + std::fabs(c) * 0x1.0p-22f; };
                *args->bounds_o = {lo(d.cx[i]), lo(d.cy[i]), lo(d.cz[i]), 0.0f,
                                   hi(d.cx[i]), hi(d.cy[i]), hi(d.cz[i]), 0.0f};
            },
            nullptr);
        const EmbreeSphereCallbacks& callbacks = embree_sphere_callbacks();
        rtcSetGeometryIntersectFunction(g, callbacks.intersect);
        rtcSetGeometryOccludedFunction(g, callbacks.occluded);
        im.attach(im.scene, g,
                  std::vector<std::int32_t>(s.object.begin(), s.object.begin() + s.count),
                  Impl::Kind::user);
    } else if (s.count > 0) {
        // Spheres: one SPHERE_POINT geometry, (x, y, z, r) per sphere, in file order.
        RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        if (!g) throw_error(im.device, "rtcNewGeometry(SPHERE_POINT)");
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), s.count));
        std::vector<std::int32_t> objects(s.count);
        for (std::uint32_t i = 0; i < s.count; ++i) {
            v[4 * i + 0] = s.cx[i], v[4 * i + 1] = s.cy[i], v[4 * i + 2] = s.cz[i];
            v[4 * i + 3] = scene.objects[s.object[i]].radius;
            objects[i] = static_cast<std::int32_t>(s.object[i]);
        }
        im.attach(im.scene, g, std::move(objects), Impl::Kind::buffers);
    }

    // Planes: one QUAD geometry, a square per plane spanned by the checker basis; with user
    // geometry in a scene of its own, instanced with the identity.
    const CompiledPlanes& p = compiled.planes;
    if (p.count > 0) {
        RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_QUAD);
        if (!g) throw_error(im.device, "rtcNewGeometry(QUAD)");
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4 * p.count));
        auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), p.count));
        // The scene's size: the diagonal of the spheres' bounding box (at least 1).
        Vec3 lo{kInfinity, kInfinity, kInfinity}, hi = -lo;
        for (std::uint32_t i = 0; i < s.count; ++i) {
            const float radius = scene.objects[s.object[i]].radius;
            const Vec3 c{s.cx[i], s.cy[i], s.cz[i]}, r{radius, radius, radius};
            lo = min(lo, c - r), hi = max(hi, c + r);
        }
        const float extent = s.count > 0 ? length(hi - lo) : 0.0f;
        const float half = kPlaneHalfSizeScale * std::max(1.0f, extent);
        std::vector<std::int32_t> objects(p.count);
        for (std::uint32_t i = 0; i < p.count; ++i) {
            const Object& o = scene.objects[p.object[i]];
            const TangentBasis tb = checker_basis(o.normal);
            // Embree splits a quad into two triangles along a diagonal, and the edge tests
            // of a triangle this large are imprecise near its edges: a diagonal through the
            // view would let rays slip between the two halves. So the point of the plane
            // nearest the eye sits at (-R/2, R/4) in the quad's (t1, t2) frame, far from
            // both diagonals (and from the edges) whichever one Embree splits along.
            const Vec3 eye = compiled.camera.eye;
            const Vec3 foot = eye - o.normal * dot(eye - o.point, o.normal);
            const Vec3 center = foot + tb.t1 * (0.5f * half) - tb.t2 * (0.25f * half);
            const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
            for (int c = 0; c < 4; ++c) {
                const Vec3 corner = center + tb.t1 * (su[c] * half) + tb.t2 * (sv[c] * half);
                v[3 * (4 * i + c) + 0] = corner.x;
                v[3 * (4 * i + c) + 1] = corner.y;
                v[3 * (4 * i + c) + 2] = corner.z;
                index[4 * i + c] = 4 * i + static_cast<unsigned>(c);
            }
            objects[i] = static_cast<std::int32_t>(p.object[i]);
        }
        if (geometry == EmbreeGeometry::user) {
            im.plane_scene = rtcNewScene(im.device);
            rtcSetSceneBuildQuality(im.plane_scene, build_quality);
            im.attach(im.plane_scene, g, std::move(objects), Impl::Kind::buffers);
            rtcCommitScene(im.plane_scene);
            RTCGeometry instance = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_INSTANCE);
            if (!instance) throw_error(im.device, "rtcNewGeometry(INSTANCE)");
            rtcSetGeometryInstancedScene(instance, im.plane_scene);
            const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
            rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
            im.attach(im.scene, instance, {}, Impl::Kind::instance);
        } else {
            im.attach(im.scene, g, std::move(objects), Impl::Kind::buffers);
        }
    }

    const auto start = std::chrono::steady_clock::now();
    rtcCommitScene(im.scene);
    im.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (rtcGetDeviceError(im.device) != RTC_ERROR_NONE || !im.last_error.empty())
        throw std::runtime_error("Embree: scene build failed: " + im.last_error);
    im.bytes_after_build = im.live_bytes.load();
}

EmbreeScene::~EmbreeScene() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->plane_scene) rtcReleaseScene(impl_->plane_scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

double EmbreeScene::build_seconds() const { return impl_->build_seconds; }

EmbreeBuildQuality EmbreeScene::build_quality() const { return impl_->quality; }

std::uint64_t EmbreeScene::sphere_builds() const { return impl_->sphere_builds.load(); }

double EmbreeScene::rebuild() {
    Impl& im = *impl_;
    const auto start = std::chrono::steady_clock::now();
    // The planes' scene first (the instance refers to it), then the top scene.
    for (RTCScene target : {im.plane_scene, im.scene}) {
        if (!target) continue;
        for (const Impl::Attached& a : im.attached) {
            if (a.scene != target) continue;
            if (a.kind == Impl::Kind::user)
                rtcSetGeometryUserPrimitiveCount(a.geometry, a.primitives);
            else if (a.kind == Impl::Kind::buffers)
                rtcUpdateGeometryBuffer(a.geometry, RTC_BUFFER_TYPE_VERTEX, 0);
            rtcCommitGeometry(a.geometry);
        }
        rtcCommitScene(target);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (rtcGetDeviceError(im.device) != RTC_ERROR_NONE || !im.last_error.empty())
        throw std::runtime_error("Embree: scene rebuild failed: " + im.last_error);
    return seconds;
}

std::int64_t EmbreeScene::memory_bytes() const { return impl_->bytes_after_build; }

std::string EmbreeScene::version() { return RTC_VERSION_STRING; }

EmbreeGeometry EmbreeScene::geometry() const { return impl_->geometry; }

std::string EmbreeScene::device_info() const {
    const auto prop = [&](RTCDeviceProperty p) {
        return rtcGetDeviceProperty(impl_->device, p);
    };
    std::string s = "embree " + version();
    s += prop(RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? ", native ray8" : ", emulated ray8";
    s += prop(RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? ", native ray16"
                                                          : ", emulated ray16";
    s += std::string(", user-geometry spheres: ") + embree_sphere_callbacks().name +
         " callbacks";
    s += prop(RTC_DEVICE_PROPERTY_TASKING_SYSTEM) == 1 ? ", TBB tasking" : ", own tasking";
    return s;
}

namespace {

RTCIntersectContext make_context(bool coherent) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    return context;
}

// What stays the same from packet to packet (Embree writes only tfar and the hit): set
// once before the first. The ID is not read back, so it stays 0.
template <int K, class RayK>
void init_packet(RayK& r, int (&valid)[K], float t_min) {
    for (int k = 0; k < K; ++k) {
        valid[k] = -1;
        r.tnear[k] = t_min;
        r.time[k] = 0.0f;
        r.mask[k] = 0xFFFFFFFFu;
        r.id[k] = 0;
        r.flags[k] = 0;
    }
}

// Lanes [first, first + K) into a K-wide packet. A full packet is K consecutive rays of
// the SoA arrays: each field one block copy (what an expert's harness does; lane-by-lane
// selects cost as much as Embree's whole traversal of a small scene). In a last, partial
// packet the lanes past `end` are off and carry a harmless ray (origin 0, direction +z,
// empty interval): Embree 3.13's emulated 16-wide calls assert that every ray of an
// 8-wide half is valid, off lanes included, and the kernels' streams hold garbage past
// their count.
template <int K, class RayK>
void set_ray_packet(RayK& r, int (&valid)[K], const EmbreeScene::RayArrays& rays,
                    std::uint32_t first, std::uint32_t end) {
    if (first + K <= end) {
        constexpr std::size_t bytes = K * sizeof(float);
        std::memcpy(r.org_x, rays.ox + first, bytes);
        std::memcpy(r.org_y, rays.oy + first, bytes);
        std::memcpy(r.org_z, rays.oz + first, bytes);
        std::memcpy(r.dir_x, rays.dx + first, bytes);
        std::memcpy(r.dir_y, rays.dy + first, bytes);
        std::memcpy(r.dir_z, rays.dz + first, bytes);
        if (rays.t_max) {
            std::memcpy(r.tfar, rays.t_max + first, bytes);
        } else {
            for (int k = 0; k < K; ++k) r.tfar[k] = kInfinity;
        }
        return;  // the rest as init_packet left it
    }
    for (int k = 0; k < K; ++k) {
        const std::uint32_t i = first + static_cast<std::uint32_t>(k);
        const bool on = i < end;
        valid[k] = on ? -1 : 0;
        r.org_x[k] = on ? rays.ox[i] : 0.0f;
        r.org_y[k] = on ? rays.oy[i] : 0.0f;
        r.org_z[k] = on ? rays.oz[i] : 0.0f;
        r.tnear[k] = rays.t_min;
        r.dir_x[k] = on ? rays.dx[i] : 0.0f;
        r.dir_y[k] = on ? rays.dy[i] : 0.0f;
        r.dir_z[k] = on ? rays.dz[i] : 1.0f;
        r.time[k] = 0.0f;
        r.tfar[k] = !on ? rays.t_min : rays.t_max ? rays.t_max[i] : kInfinity;
        r.mask[k] = 0xFFFFFFFFu;
        r.id[k] = i;
        r.flags[k] = 0;
    }
}

void set_ray(RTCRay& r, const EmbreeScene::RayArrays& rays, std::uint32_t i) {
    r.org_x = rays.ox[i], r.org_y = rays.oy[i], r.org_z = rays.oz[i];
    r.tnear = rays.t_min;
    r.dir_x = rays.dx[i], r.dir_y = rays.dy[i], r.dir_z = rays.dz[i];
    r.time = 0.0f;
    r.tfar = rays.t_max ? rays.t_max[i] : kInfinity;
    r.mask = 0xFFFFFFFFu;
    r.id = i;
    r.flags = 0;
}

EmbreeScene::RayArrays arrays_of(const RaySet& rays, std::uint32_t first) {
    return {rays.ox.data() + first,    rays.oy.data() + first,
            rays.oz.data() + first,    rays.dx.data() + first,
            rays.dy.data() + first,    rays.dz.data() + first,
            rays.t_max.data() + first, rays.t_min};
}

// K-wide packets: rtcIntersect8 / rtcIntersect16 and their occluded twins.
template <int K>
struct Packet;
template <>
struct Packet<8> {
    using RayHit = RTCRayHit8;
    using Ray = RTCRay8;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* r) {
        rtcIntersect8(v, s, c, r);
    }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, Ray* r) {
        rtcOccluded8(v, s, c, r);
    }
};
template <>
struct Packet<16> {
    using RayHit = RTCRayHit16;
    using Ray = RTCRay16;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* r) {
        rtcIntersect16(v, s, c, r);
    }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, Ray* r) {
        rtcOccluded16(v, s, c, r);
    }
};

}  // namespace

template <int K>
void intersect_packets(const EmbreeScene::Impl& im, RTCIntersectContext& context,
                       const EmbreeScene::RayArrays& rays, std::uint32_t count, float* t,
                       std::int32_t* object) {
    alignas(64) typename Packet<K>::RayHit rh;
    alignas(64) int valid[K];
    init_packet<K>(rh.ray, valid, rays.t_min);
    for (std::uint32_t base = 0; base < count; base += K) {
        set_ray_packet<K>(rh.ray, valid, rays, base, count);
        static_assert(RTC_INVALID_GEOMETRY_ID == 0xFFFFFFFFu);
        std::memset(rh.hit.geomID, 0xFF, sizeof rh.hit.geomID);
        std::memset(rh.hit.instID[0], 0xFF, sizeof rh.hit.instID[0]);
        Packet<K>::intersect(valid, im.scene, &context, &rh);
        const std::uint32_t lanes = std::min<std::uint32_t>(K, count - base);
        for (std::uint32_t k = 0; k < lanes; ++k) {
            const std::int32_t o =
                im.object(rh.hit.geomID[k], rh.hit.primID[k], rh.hit.instID[0][k]);
            object[base + k] = o;
            t[base + k] = o == kernels::kNoHit ? kInfinity : rh.ray.tfar[k];
        }
    }
}

template <int K>
void occluded_packets(const EmbreeScene::Impl& im, RTCIntersectContext& context,
                      const EmbreeScene::RayArrays& rays, std::uint32_t count,
                      std::uint32_t* occluded) {
    alignas(64) typename Packet<K>::Ray r;
    alignas(64) int valid[K];
    init_packet<K>(r, valid, rays.t_min);
    for (std::uint32_t base = 0; base < count; base += K) {
        set_ray_packet<K>(r, valid, rays, base, count);
        Packet<K>::occluded(valid, im.scene, &context, &r);
        for (std::uint32_t k = 0; k < K && base + k < count; ++k)
            occluded[base + k] = r.tfar[k] < 0.0f ? 1u : 0u;  // occluded: tfar = -inf
    }
}

void EmbreeScene::intersect(EmbreeMode mode, const RayArrays& rays, std::uint32_t count,
                            float* t, std::int32_t* object, bool coherent) const {
    const Impl& im = *impl_;
    RTCIntersectContext context = make_context(coherent);
    switch (mode) {
        case EmbreeMode::packet8:
            return intersect_packets<8>(im, context, rays, count, t, object);
        case EmbreeMode::packet16:
            return intersect_packets<16>(im, context, rays, count, t, object);
        case EmbreeMode::single:
            break;
    }
    for (std::uint32_t i = 0; i < count; ++i) {
        RTCRayHit rh;
        set_ray(rh.ray, rays, i);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(im.scene, &context, &rh);
        object[i] = im.object(rh.hit.geomID, rh.hit.primID, rh.hit.instID[0]);
        t[i] = object[i] == kernels::kNoHit ? kInfinity : rh.ray.tfar;
    }
}

void EmbreeScene::occluded(EmbreeMode mode, const RayArrays& rays, std::uint32_t count,
                           std::uint32_t* occluded, bool coherent) const {
    const Impl& im = *impl_;
    RTCIntersectContext context = make_context(coherent);
    switch (mode) {
        case EmbreeMode::packet8:
            return occluded_packets<8>(im, context, rays, count, occluded);
        case EmbreeMode::packet16:
            return occluded_packets<16>(im, context, rays, count, occluded);
        case EmbreeMode::single:
            break;
    }
    for (std::uint32_t i = 0; i < count; ++i) {
        RTCRay r;
        set_ray(r, rays, i);
        rtcOccluded1(im.scene, &context, &r);
        occluded[i] = r.tfar < 0.0f ? 1u : 0u;
    }
}

void EmbreeScene::intersect(EmbreeMode mode, const RaySet& rays, std::uint32_t first,
                            std::uint32_t n, HitSet& hits, bool coherent) const {
    intersect(mode, arrays_of(rays, first), n, hits.t.data() + first,
              hits.object.data() + first, coherent);
}

void EmbreeScene::occluded(EmbreeMode mode, const RaySet& rays, std::uint32_t first,
                           std::uint32_t n, HitSet& hits, bool coherent) const {
    // The 0/1 flags land in the object column itself (4 bytes each), then become ids: no
    // allocation inside the timed loop.
    std::int32_t* object = hits.object.data() + first;
    occluded(mode, arrays_of(rays, first), n, reinterpret_cast<std::uint32_t*>(object),
             coherent);
    for (std::uint32_t i = 0; i < n; ++i) object[i] = object[i] ? kOccluded : kernels::kNoHit;
}

}  // namespace octray::bench
