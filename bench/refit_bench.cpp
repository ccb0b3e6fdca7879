// The per-frame update of a scene whose spheres all move, octray against Embree, in one
// run: octray's PreparedScene::update (the posed spheres written into the compiled arrays,
// the BVH refitted, its cost checked against the rebuild limit) and Embree 3's refit of
// the same spheres as user geometry (RTC_SCENE_FLAG_DYNAMIC, RTC_BUILD_QUALITY_REFIT: the
// posed spheres copied into its arrays, rtcCommitGeometry + rtcCommitScene). Both start
// from the posed Scene and end with a tree ready to trace; frames alternate between two
// poses (every sphere moved by up to half its radius per axis), so the refit tree never
// needs a rebuild. Reported in microseconds per update and spheres per second; compare the two
// rows of one run (bench/README.md, "Refit").

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/packet_renderer.h"
#include "scene/load.h"

#if OCTRAY_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using namespace octray;

constexpr int kThreads = 2;

// random:N and the same scene with every sphere moved: frame f poses moved[f % 2].
struct MovingScene {
    Scene poses[2];

    explicit MovingScene(int spheres) {
        poses[0] = load_scene("random:" + std::to_string(spheres) + ",width=64,height=64");
        poses[1] = poses[0];
        std::uint32_t state = 7;  // xorshift32: the moves need no quality
        const auto offset = [&state] {
            state ^= state << 13, state ^= state >> 17, state ^= state << 5;
            return static_cast<float>(state >> 8) * 0x1.0p-24f - 0.5f;
        };
        for (Object& o : poses[1].objects) {
            if (o.type != ObjectType::sphere) continue;
            const float dx = offset(), dy = offset(), dz = offset();
            o.center = o.center + Vec3{dx, dy, dz} * o.radius;
        }
        validate_scene(poses[1]);
    }
};

const MovingScene& moving_scene(int spheres) {
    static std::map<int, MovingScene> scenes;
    auto it = scenes.find(spheres);
    if (it == scenes.end()) it = scenes.emplace(spheres, MovingScene(spheres)).first;
    return it->second;
}

void report(benchmark::State& state, int spheres) {
    state.counters["spheres/s"] = benchmark::Counter(
        static_cast<double>(spheres), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_OctrayUpdate(benchmark::State& state) {
    const int spheres = static_cast<int>(state.range(0));
    const MovingScene& scene = moving_scene(spheres);
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, kThreads);
    PreparedScene prepared(scene.poses[0], Accel::automatic, kThreads);
    std::size_t frame = 0, rebuilds = 0;
    for (auto _ : state) {
        const PreparedScene::Update u = prepared.update(scene.poses[++frame % 2]);
        rebuilds += u.rebuilt;
        benchmark::DoNotOptimize(prepared.bvh());
    }
    if (rebuilds > 0) state.SkipWithError("the refit tree was rebuilt");
    report(state, spheres);
}

#if OCTRAY_HAVE_EMBREE

struct EmbreeSpheres {
    std::vector<float> cx, cy, cz, r;
};

void embree_bounds(const RTCBoundsFunctionArguments* args) {
    const auto& s = *static_cast<const EmbreeSpheres*>(args->geometryUserPtr);
    const unsigned i = args->primID;
    *args->bounds_o = {s.cx[i] - s.r[i], s.cy[i] - s.r[i], s.cz[i] - s.r[i], 0.0f,
                       s.cx[i] + s.r[i], s.cy[i] + s.r[i], s.cz[i] + s.r[i], 0.0f};
}

// The posed spheres into Embree's arrays (what update_compiled_spheres does for octray).
void copy_spheres(const Scene& scene, EmbreeSpheres& s) {
    std::size_t k = 0;
    for (const Object& o : scene.objects) {
        if (o.type != ObjectType::sphere) continue;
        s.cx[k] = o.center.x, s.cy[k] = o.center.y, s.cz[k] = o.center.z, s.r[k] = o.radius;
        ++k;
    }
}

void BM_EmbreeRefit(benchmark::State& state) {
    const int spheres = static_cast<int>(state.range(0));
    const MovingScene& scene = moving_scene(spheres);
    EmbreeSpheres s;
    for (auto* v : {&s.cx, &s.cy, &s.cz, &s.r}) v->resize(static_cast<std::size_t>(spheres));
    copy_spheres(scene.poses[0], s);
    RTCDevice device = rtcNewDevice(("threads=" + std::to_string(kThreads)).c_str());
    if (!device) throw std::runtime_error("rtcNewDevice failed");
    RTCScene rtc_scene = rtcNewScene(device);
    // A geometry's own build quality (REFIT) is used under a scene of LOW quality only.
    rtcSetSceneFlags(rtc_scene, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(rtc_scene, RTC_BUILD_QUALITY_LOW);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(spheres));
    rtcSetGeometryUserData(geometry, &s);
    rtcSetGeometryBoundsFunction(geometry, embree_bounds, nullptr);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(rtc_scene, geometry);
    rtcCommitScene(rtc_scene);
    std::size_t frame = 0;
    for (auto _ : state) {
        copy_spheres(scene.poses[++frame % 2], s);
        rtcCommitGeometry(geometry);
        rtcCommitScene(rtc_scene);
    }
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) state.SkipWithError("Embree error");
    rtcReleaseGeometry(geometry);
    rtcReleaseScene(rtc_scene);
    rtcReleaseDevice(device);
    report(state, spheres);
}

#endif

void sizes(benchmark::internal::Benchmark* b) {
    b->Arg(1024)->Arg(65536)->Arg(1048576)->Unit(benchmark::kMicrosecond)->UseRealTime();
}

BENCHMARK(BM_OctrayUpdate)->Apply(sizes);
#if OCTRAY_HAVE_EMBREE
BENCHMARK(BM_EmbreeRefit)->Apply(sizes);
#endif

}  // namespace

BENCHMARK_MAIN();
