#pragma once
// The scene as authored: what a JSON file or a built-in generator describes, in file
// order, before it is compiled into the flat SoA layout the packet kernels read.
// Field semantics: docs/rendering-model.md; defaults: docs/scene-format.md.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/color.h"
#include "core/vec3.h"
#include "scene/animation.h"

namespace octray {

enum class CameraType { pinhole, orthographic, thinlens, fisheye };

struct Camera {
    CameraType type = CameraType::pinhole;
    Vec3 eye{0.0f, 0.0f, 5.0f};
    Vec3 lookat{0.0f, 0.0f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    float fov = 50.0f;            // degrees, horizontal (pinhole, thinlens, fisheye)
    float width = 2.0f;           // film width in world units (orthographic)
    float aperture = 0.0f;        // lens radius (thinlens)
    float focus_distance = 1.0f;  // distance of the focal plane along the view (thinlens)
    // "fov_units": "degrees" in the file: a fov below kSmallFovDegrees is meant as given,
    // so scene_warnings() says nothing about it.
    bool fov_units_stated = false;
};

// A pinhole or thin-lens fov below this many degrees is legal but is almost always an
// angle in radians by mistake: scene_warnings() names it.
inline constexpr float kSmallFovDegrees = 2.0f;

struct Checker {
    Rgb color;          // Cd2, used where floor(P.T1/size) + floor(P.T2/size) is odd
    float size = 1.0f;  // square size in world units
};

struct Material {
    Rgb color{0.8f, 0.8f, 0.8f};  // Cd
    float kd = 1.0f;
    float ks = 0.0f;
    float shininess = 32.0f;
    Rgb reflect{0.0f, 0.0f, 0.0f};  // kr
    float transmit = 0.0f;          // kt
    float ior = 1.5f;
    std::optional<Checker> checker;  // used on planes only
};

enum class ObjectType { sphere, plane };

struct Object {
    ObjectType type = ObjectType::sphere;
    std::string name;            // optional; unique when set (animation targets)
    std::uint32_t material = 0;  // index into Scene::materials
    // sphere
    Vec3 center;
    float radius = 1.0f;
    // plane
    Vec3 point;
    Vec3 normal{0.0f, 1.0f, 0.0f};  // unit length (normalised on load)
};

enum class LightType { point, directional };

struct Light {
    LightType type = LightType::point;
    Vec3 position;   // point
    Vec3 direction;  // directional: the way the light travels
    Rgb color{1.0f, 1.0f, 1.0f};
    bool inverse_square = false;  // point: "falloff": "inverse-square"
};

enum class BackgroundType { constant, gradient };

struct Background {
    BackgroundType type = BackgroundType::constant;
    Rgb color;   // constant
    Rgb bottom;  // gradient
    Rgb top;
};

struct ImageSettings {
    int width = 640;
    int height = 480;
    int spp = 1;
};

struct RenderSettings {
    int max_depth = 5;
    std::uint64_t seed = 0;
    std::optional<float> epsilon;  // overrides the self-intersection rule
};

struct NamedMaterial {
    std::string name;  // empty for an inline material
    Material material;
};

struct Scene {
    std::string source;  // file path or built-in spec, for messages and EXR attributes
    ImageSettings image;
    Camera camera;
    Background background;
    Rgb ambient{0.0f, 0.0f, 0.0f};
    RenderSettings render;
    std::vector<NamedMaterial> materials;  // named ones in file order, then inline ones
    std::vector<Object> objects;           // file order: ties go to the first listed
    std::vector<Light> lights;
    // Key frames (scene/animation.h); empty for a still scene. The fields above are the
    // authored pose; scene_at_frame() gives the still scene of one frame.
    std::optional<Animation> animation;
};

// What is legal in `scene` but probably not meant, one message per finding, each naming the
// file (scene.source) and the JSON path: a pinhole or thin-lens fov (the camera's or an
// animation key's) below kSmallFovDegrees, unless the camera states "fov_units". The
// command line prints them on stderr unless --quiet.
std::vector<std::string> scene_warnings(const Scene& scene);

// ε_s of the self-intersection rule: render.epsilon if set, else
// 1e-4 * max(1, diagonal of the bounding box of all spheres); planes are ignored.
float self_intersection_epsilon(const Scene& scene);

// The spheres' bounding box, as self_intersection_epsilon measures it; empty (lo > hi)
// without spheres. Boxes of parts of the spheres unite with `unite`, in any order, to the
// same bits.
struct SphereBox {
    Vec3 lo{3.0e38f, 3.0e38f, 3.0e38f}, hi{-3.0e38f, -3.0e38f, -3.0e38f};
    bool any = false;

    void add(const Object& sphere) {
        const Vec3 r{sphere.radius, sphere.radius, sphere.radius};
        lo = min(lo, sphere.center - r);
        hi = max(hi, sphere.center + r);
        any = true;
    }
    static SphereBox unite(const SphereBox& a, const SphereBox& b) {
        return {min(a.lo, b.lo), max(a.hi, b.hi), a.any || b.any};
    }
};

// self_intersection_epsilon of `scene` whose spheres' box is `box`.
float self_intersection_epsilon(const Scene& scene, const SphereBox& box);

// The checker's tangent basis for a plane normal N: T1 is the world axis along which |N|
// has its smallest component (x, then y, then z on ties), made orthogonal to N and
// normalised; T2 = T1 x N.
struct TangentBasis {
    Vec3 t1, t2;
};
TangentBasis checker_basis(Vec3 normal);

}  // namespace octray
