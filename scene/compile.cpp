#include "scene/compile.h"

#include <math.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace octray {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// At least one full packet, so that a kernel gathering for a lane that missed can always
// read entry 0.
std::uint32_t padded(std::uint32_t n) {
    const std::uint32_t rounded =
        (n + kCompiledPadding - 1) / kCompiledPadding * kCompiledPadding;
    return rounded > 0 ? rounded : kCompiledPadding;
}

// Sizes an array of `count` entries that the caller writes to `padded` entries, the ones
// past `count` set to `filler` (NaN geometry never hits). The entries below `count` are
// left unwritten: zero-filling 22 arrays of a million entries on one thread before the
// parallel fill wrote them again was most of compile_scene's time on random:1048576.
template <class T>
void size_for(GeometryArray<T>& v, std::uint32_t count, std::uint32_t padded, T filler) {
    v.resize(padded);
    std::fill(v.begin() + count, v.end(), filler);
}
template <class T>
void pad(AlignedVector<T>& v, std::uint32_t n, T filler) {
    v.resize(n, filler);
}

// The largest x in [0, 1] with powf(x, n) == 0, by bisection over the float bit patterns
// (powf is monotonic in x on [0, 1] for n > 0); -1 when powf(0, n) is not 0 (n <= 0).
float pow_zero_below(float n) {
    if (!(powf(0.0f, n) == 0.0f)) return -1.0f;
    std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.0f);  // powf(lo) == 0
    if (powf(1.0f, n) == 0.0f) return 1.0f;
    while (hi - lo > 1) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        if (powf(std::bit_cast<float>(mid), n) == 0.0f)
            lo = mid;
        else
            hi = mid;
    }
    return std::bit_cast<float>(lo);
}

}  // namespace

void set_compiled_camera(CompiledScene& scene, const Camera& camera) {
    scene.camera = make_camera_frame(camera, scene.width, scene.height);
    scene.background_up = normalize(camera.up);
}

namespace {

// Where a sphere is and how large: compiled sphere si, file object k. compile_scene and
// update_compiled_spheres both write them here, so an updated scene holds the bits a
// fresh compile would.
void write_sphere(CompiledScene& out, std::uint32_t si, std::uint32_t k, const Object& obj) {
    CompiledSpheres& s = out.spheres;
    s.cx[si] = obj.center.x, s.cy[si] = obj.center.y, s.cz[si] = obj.center.z;
    s.r2[si] = obj.radius * obj.radius;
    float* record = out.objects.record.data() + std::size_t{k} * kObjectRecordFloats;
    record[kRecordCx] = obj.center.x, record[kRecordCy] = obj.center.y;
    record[kRecordCz] = obj.center.z;
}

}  // namespace

void update_compiled_spheres(CompiledScene& out, const Scene& scene) {
    if (scene.objects.size() != out.objects.count)
        throw std::invalid_argument(
            "update_compiled_spheres: the scene has " + std::to_string(scene.objects.size()) +
            " objects, the compiled one " + std::to_string(out.objects.count));
    // The spheres' box (the self-intersection epsilon follows it) in the same pass.
    const CompiledSpheres& s = out.spheres;
    const SphereBox box = tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(0, s.count, 1u << 14), SphereBox{},
        [&](const tbb::blocked_range<std::uint32_t>& r, SphereBox part) {
            for (std::uint32_t si = r.begin(); si < r.end(); ++si) {
                const std::uint32_t k = s.object[si];
                write_sphere(out, si, k, scene.objects[k]);
                part.add(scene.objects[k]);
            }
            return part;
        },
        SphereBox::unite);
    out.epsilon = self_intersection_epsilon(scene, box);
}

CompiledScene compile_scene(const Scene& scene) {
    const auto start = std::chrono::steady_clock::now();
    if (scene.objects.size() > (1u << 24))
        throw std::invalid_argument("more than 2^24 objects cannot be compiled");

    CompiledScene out;
    out.background = scene.background;
    out.ambient = scene.ambient;
    out.max_depth = scene.render.max_depth;
    out.spp = scene.image.spp;
    out.seed = scene.render.seed;
    out.width = scene.image.width;
    out.height = scene.image.height;
    set_compiled_camera(out, scene.camera);

    // Geometry: spheres and planes each in file order, and the per-object table. Every
    // array is sized (and padded, with its filler) up front, then filled by index in
    // parallel over blocks of objects: a first pass counts each block's planes, so each
    // block knows where its spheres and planes go. (One push_back per array and object,
    // not inlined, took most of compile_scene's time on random:1048576.)
    CompiledSpheres& s = out.spheres;
    CompiledPlanes& p = out.planes;
    CompiledObjects& o = out.objects;
    const auto objects = static_cast<std::uint32_t>(scene.objects.size());
    constexpr std::uint32_t kBlock = 1u << 14;
    const std::uint32_t blocks = (objects + kBlock - 1) / kBlock;
    std::vector<std::uint32_t> planes_before(blocks + 1, 0);
    // Whether each block holds a checkered plane (bytes, not vector<bool>: written in
    // parallel).
    std::vector<std::uint8_t> block_checkers(blocks, 0);
    tbb::parallel_for(std::uint32_t{0}, blocks, [&](std::uint32_t block) {
        std::uint32_t planes = 0;
        bool checkers = false;
        const std::uint32_t end = std::min(objects, (block + 1) * kBlock);
        for (std::uint32_t k = block * kBlock; k < end; ++k) {
            const Object& obj = scene.objects[k];
            const bool plane = obj.type == ObjectType::plane;
            planes += plane;
            checkers = checkers || (plane && scene.materials[obj.material].material.checker);
        }
        planes_before[block + 1] = planes;
        block_checkers[block] = checkers;
    });
    for (std::uint32_t block = 0; block < blocks; ++block)
        planes_before[block + 1] += planes_before[block];
    // Shading reads the tangent columns only where a lane hit a checkered plane: without
    // one they stay empty (random:1048576: 24 MB of zeros, written and faulted in, gone).
    const bool checker_planes =
        std::find(block_checkers.begin(), block_checkers.end(), 1) != block_checkers.end();

    s.count = objects - planes_before[blocks];
    s.padded_count = padded(s.count);
    for (auto* v : {&s.cx, &s.cy, &s.cz, &s.r2}) size_for(*v, s.count, s.padded_count, kNaN);
    size_for(s.object, s.count, s.padded_count, std::numeric_limits<std::uint32_t>::max());

    p.count = planes_before[blocks];
    p.padded_count = padded(p.count);
    for (auto* v : {&p.nx, &p.ny, &p.nz, &p.d}) size_for(*v, p.count, p.padded_count, kNaN);
    size_for(p.object, p.count, p.padded_count, std::numeric_limits<std::uint32_t>::max());

    o.count = objects;
    o.padded_count = padded(o.count);
    size_for(o.record, o.count * kObjectRecordFloats, o.padded_count * kObjectRecordFloats,
             0.0f);  // padding: a sphere at the origin of material 0 (no hit carries its id)
    if (checker_planes)
        for (auto* v : {&o.t1x, &o.t1y, &o.t1z, &o.t2x, &o.t2y, &o.t2z})
            size_for(*v, o.count, o.padded_count, 0.0f);

    // Every entry below the counts, each array's own and (for an object) the other kind's
    // zeros: a sphere has no normal or tangents, a plane no center. The spheres' box (the
    // self-intersection epsilon follows it) in the same pass: min and max give the same
    // box in any order.
    std::vector<SphereBox> block_boxes(blocks);
    tbb::parallel_for(std::uint32_t{0}, blocks, [&](std::uint32_t block) {
        SphereBox box;
        std::uint32_t pi = planes_before[block];
        std::uint32_t si = block * kBlock - pi;
        const std::uint32_t end = std::min(objects, (block + 1) * kBlock);
        for (std::uint32_t k = block * kBlock; k < end; ++k) {
            const Object& obj = scene.objects[k];
            const Material& m = scene.materials[obj.material].material;
            const bool plane = obj.type == ObjectType::plane;
            float* record = o.record.data() + std::size_t{k} * kObjectRecordFloats;
            record[kRecordKind] = !plane      ? kKindSphere
                                  : m.checker ? kKindCheckerPlane
                                              : kKindPlane;
            record[kRecordMaterial] = std::bit_cast<float>(obj.material);
            if (plane) {
                p.nx[pi] = obj.normal.x, p.ny[pi] = obj.normal.y, p.nz[pi] = obj.normal.z;
                p.d[pi] = dot(obj.point, obj.normal);
                p.object[pi] = k;
                ++pi;
                record[kRecordCx] = record[kRecordCy] = record[kRecordCz] = 0.0f;
                record[kRecordNx] = obj.normal.x, record[kRecordNy] = obj.normal.y;
                record[kRecordNz] = obj.normal.z;
                if (checker_planes) {
                    const TangentBasis tb = checker_basis(obj.normal);
                    o.t1x[k] = tb.t1.x, o.t1y[k] = tb.t1.y, o.t1z[k] = tb.t1.z;
                    o.t2x[k] = tb.t2.x, o.t2y[k] = tb.t2.y, o.t2z[k] = tb.t2.z;
                }
            } else {
                s.object[si] = k;
                write_sphere(out, si, k, obj);
                box.add(obj);
                ++si;
                record[kRecordNx] = record[kRecordNy] = record[kRecordNz] = 0.0f;
                if (checker_planes) {
                    o.t1x[k] = o.t1y[k] = o.t1z[k] = 0.0f;
                    o.t2x[k] = o.t2y[k] = o.t2z[k] = 0.0f;
                }
            }
        }
        block_boxes[block] = box;
    });
    SphereBox box;
    for (const SphereBox& b : block_boxes) box = SphereBox::unite(box, b);
    out.epsilon = self_intersection_epsilon(scene, box);

    // Materials.
    CompiledMaterials& m = out.materials;
    for (const NamedMaterial& nm : scene.materials) {
        const Material& mat = nm.material;
        m.cd_r.push_back(mat.color.r), m.cd_g.push_back(mat.color.g);
        m.cd_b.push_back(mat.color.b);
        m.kd.push_back(mat.kd), m.ks.push_back(mat.ks), m.shininess.push_back(mat.shininess);
        m.kr_r.push_back(mat.reflect.r), m.kr_g.push_back(mat.reflect.g);
        m.kr_b.push_back(mat.reflect.b);
        m.kt.push_back(mat.transmit), m.ior.push_back(mat.ior);
        m.pow_zero_below.push_back(pow_zero_below(mat.shininess));
        const Checker checker = mat.checker.value_or(Checker{mat.color, 1.0f});
        m.checker_r.push_back(checker.color.r), m.checker_g.push_back(checker.color.g);
        m.checker_b.push_back(checker.color.b), m.checker_size.push_back(checker.size);
    }
    m.count = static_cast<std::uint32_t>(scene.materials.size());
    m.padded_count = padded(m.count);
    for (auto* v : {&m.cd_r, &m.cd_g, &m.cd_b, &m.kd, &m.ks, &m.shininess, &m.kr_r, &m.kr_g,
                    &m.kr_b, &m.kt, &m.checker_r, &m.checker_g, &m.checker_b})
        pad(*v, m.padded_count, 0.0f);
    pad(m.ior, m.padded_count, 1.0f);
    pad(m.pow_zero_below, m.padded_count, -1.0f);
    pad(m.checker_size, m.padded_count, 1.0f);

    // Lights.
    CompiledLights& l = out.lights;
    for (const Light& light : scene.lights) {
        const bool directional = light.type == LightType::directional;
        l.directional.push_back(directional ? 1u : 0u);
        l.inverse_square.push_back(!directional && light.inverse_square ? 1u : 0u);
        l.px.push_back(light.position.x), l.py.push_back(light.position.y);
        l.pz.push_back(light.position.z);
        const Vec3 dir = directional ? -normalize(light.direction) : Vec3{};
        l.lx.push_back(dir.x), l.ly.push_back(dir.y), l.lz.push_back(dir.z);
        l.r.push_back(light.color.r), l.g.push_back(light.color.g),
            l.b.push_back(light.color.b);
    }
    l.count = static_cast<std::uint32_t>(scene.lights.size());
    l.padded_count = padded(l.count);
    for (auto* v : {&l.directional, &l.inverse_square}) pad(*v, l.padded_count, 0u);
    for (auto* v : {&l.px, &l.py, &l.pz, &l.lx, &l.ly, &l.lz, &l.r, &l.g, &l.b})
        pad(*v, l.padded_count, 0.0f);

    out.compile_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace octray
