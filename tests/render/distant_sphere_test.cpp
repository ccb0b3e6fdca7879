// Small spheres far from a pinhole camera with a narrow field of view: the case where the
// textbook discriminant b^2 - a c' is all rounding (b^2 and a c' of size D^2, their
// difference of size r^2) and both paths drew stripes and speckle, with highlights near
// 1e30 where a hit off the surface made the normal long. Each render, on both paths, every
// ISA this CPU has and the BVH too, must show a disc: per pixel row, as many hit pixels as
// the analytic disc covers (within one pixel at its edges), in one run, and no pixel
// brighter than the light can make it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "kernels/dispatch.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene_builders.h"

namespace octray {
namespace {

constexpr int kSize = 64;           // image width and height
constexpr double kDiscPixels = 20;  // the disc's radius on the image, in pixels

struct DVec {
    double x, y, z;
};
DVec operator-(DVec a, DVec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
DVec operator+(DVec a, DVec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
DVec operator*(DVec a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(DVec a, DVec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
DVec cross(DVec a, DVec b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
DVec unit(DVec a) { return a * (1.0 / std::sqrt(dot(a, a))); }
DVec dvec(Vec3 v) { return {v.x, v.y, v.z}; }

// A unit sphere `distance` from the eye along an oblique direction (every coordinate
// matters), a field of view that makes it kDiscPixels in radius, a light beside the eye.
Scene distant_sphere_scene(double distance) {
    Scene s = testing::empty_scene(kSize, kSize);
    const DVec eye{3.0, -2.0, 7.0};
    const DVec center = eye + unit({0.3, 0.2, -1.0}) * distance;
    s.camera.eye = {3.0f, -2.0f, 7.0f};
    s.camera.lookat = {static_cast<float>(center.x), static_cast<float>(center.y),
                       static_cast<float>(center.z)};
    // The disc's radius on the film plane at distance 1 is r / sqrt(D^2 - r^2).
    const double rho = 1.0 / std::sqrt(distance * distance - 1.0);
    s.camera.fov = static_cast<float>(2.0 * std::atan(rho * (kSize / 2.0) / kDiscPixels) *
                                      180.0 / std::numbers::pi);
    s.ambient = Rgb(0.05f);
    Material m;
    m.color = {0.8f, 0.6f, 0.4f};
    m.ks = 0.5f;
    m.shininess = 32.0f;
    testing::add_sphere(s, s.camera.lookat, 1.0f, testing::add_material(s, m));
    const DVec light = eye + DVec{distance * 0.05, distance * 0.05, 0.0};
    testing::add_point_light(
        s,
        {static_cast<float>(light.x), static_cast<float>(light.y), static_cast<float>(light.z)},
        Rgb(1.0f));
    return s;
}

// Which pixel centers' rays meet the true sphere, in double precision from the camera
// model (pinhole: direction Ln + x u + y v, row 0 at the top).
std::vector<int> analytic_row_coverage(const Scene& s) {
    const DVec eye = dvec(s.camera.eye), center = dvec(s.objects[0].center);
    const DVec ln = unit(dvec(s.camera.lookat) - eye);
    const double half = std::tan(static_cast<double>(s.camera.fov) * std::numbers::pi / 360.0);
    const DVec u = unit(cross(ln, dvec(s.camera.up))) * half;
    const DVec v = unit(cross(u, ln)) * half;  // aspect 1
    const double r = s.objects[0].radius;
    std::vector<int> rows(kSize, 0);
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            const double x = 2.0 * (i + 0.5) / kSize - 1.0, y = 1.0 - 2.0 * (j + 0.5) / kSize;
            const DVec d = unit(ln + u * x + v * y);
            const DVec oc = eye - center;
            const double b = dot(oc, d);
            const DVec l = oc - d * b;  // center to the ray's nearest point
            if (dot(l, l) <= r * r && b < 0.0) ++rows[j];
        }
    return rows;
}

// The brightest a pixel can be: ambient Cd kd + L (kd Cd + ks), per channel.
Rgb brightest(const Scene& s) {
    const Material& m = s.materials[s.objects[0].material].material;
    const Rgb l = s.lights[0].color;
    return s.ambient * (m.color * m.kd) + l * (m.color * m.kd + Rgb(m.ks));
}

void expect_disc(const Scene& s, const Image& image, const std::string& what) {
    SCOPED_TRACE(what);
    const std::vector<int> want = analytic_row_coverage(s);
    const Rgb top = brightest(s) * 1.0001f;  // room for the rounding of the sums
    int covered_rows = 0, worst_row_error = 0, over = 0, nonfinite = 0;
    for (int j = 0; j < kSize; ++j) {
        int hits = 0, runs = 0;
        bool previous = false;
        for (int i = 0; i < kSize; ++i) {
            const Rgb p = rgb_at(image, i, j);
            if (!is_finite(p)) ++nonfinite;
            if (p.r > top.r || p.g > top.g || p.b > top.b) ++over;
            // Background is black and ambient lights every hit: a hit is a non-black pixel.
            const bool hit = p.r > 0.0f || p.g > 0.0f || p.b > 0.0f;
            hits += hit ? 1 : 0;
            runs += hit && !previous ? 1 : 0;
            previous = hit;
        }
        EXPECT_LE(runs, 1) << "row " << j << " is not one run of hit pixels (speckle)";
        worst_row_error = std::max(worst_row_error, std::abs(hits - want[j]));
        covered_rows += hits > 0 ? 1 : 0;
    }
    EXPECT_LE(worst_row_error, 1) << "a row's hit pixels differ from the analytic disc's";
    // The disc is there at all: about 2 * kDiscPixels rows.
    EXPECT_GE(covered_rows, 2 * kDiscPixels - 2);
    EXPECT_EQ(nonfinite, 0);
    EXPECT_EQ(over, 0) << "pixels brighter than ambient + diffuse + highlight allow";
}

class DistantSphere : public ::testing::TestWithParam<double> {};

TEST_P(DistantSphere, RendersAsADiscOnBothPaths) {
    const Scene s = distant_sphere_scene(GetParam());
    const RenderResult ref = render_reference(s, {});
    expect_disc(s, ref.image, "scalar reference");
    for (Isa isa : supported_isas())
        for (Accel accel : {Accel::none, Accel::bvh}) {
            RenderOptions options;
            options.accel = accel;
            const RenderResult simd = render_packet(s, options, isa);
            const std::string what =
                std::string("simd ") + isa_name(isa) + " accel " + accel_name(accel);
            expect_disc(s, simd.image, what);
            std::size_t differing = 0;
            for (std::size_t k = 0; k < ref.image.pixel_count(); ++k)
                differing += rgb_at(ref.image, k) == rgb_at(simd.image, k) ? 0 : 1;
            EXPECT_EQ(differing, 0u) << what << ": pixels not bit-identical to the reference";
        }
}

// 10^2, 10^3 and 10^4 radii from the eye.
INSTANTIATE_TEST_SUITE_P(Radii, DistantSphere, ::testing::Values(1e2, 1e3, 1e4),
                         [](const ::testing::TestParamInfo<double>& info) {
                             return "distance_" + std::to_string(static_cast<int>(info.param));
                         });

// The shading normal is unit length wherever a hit lands, and the hit lies on the sphere
// to within rounding of its distance: for a unit sphere 10^4 away, |P - c| is 1 to within
// ~1e-3 (the textbook form put hits many radii off).
TEST(DistantSphereHit, NormalIsUnitAndPointOnTheSphere) {
    const Scene s = distant_sphere_scene(1e4);
    const ReferenceTracer tracer(s);
    int hits = 0;
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            const auto ray = tracer.camera_ray(i, j, 0, 0);
            ASSERT_TRUE(ray);
            const auto hit = tracer.intersect(*ray);
            if (!hit) continue;
            ++hits;
            EXPECT_NEAR(length(hit->normal), 1.0f, 1e-6f) << i << "," << j;
            EXPECT_NEAR(length(hit->point - s.objects[0].center), 1.0f, 2e-3f) << i << "," << j;
        }
    EXPECT_GT(hits, 1000);
}

}  // namespace
}  // namespace octray
