// Baseline code (no ISA flags): the scene view is made once per prepared scene.

#include "render/prepare/scene_view.h"

#include <numbers>

namespace octray {

static_assert(kCompiledPadding % kernels::kSceneArrayPadding == 0);

kernels::SceneView make_scene_view(const CompiledScene& c) {
    kernels::SceneView v{};
    const CompiledSpheres& s = c.spheres;
    v.sphere_count = s.count;
    v.sphere_cx = s.cx.data(), v.sphere_cy = s.cy.data(), v.sphere_cz = s.cz.data();
    v.sphere_r2 = s.r2.data();
    v.sphere_object = s.object.data();

    const CompiledPlanes& p = c.planes;
    v.plane_count = p.count;
    v.plane_nx = p.nx.data(), v.plane_ny = p.ny.data(), v.plane_nz = p.nz.data();
    v.plane_d = p.d.data();
    v.plane_object = p.object.data();

    const CompiledObjects& o = c.objects;
    v.object_count = o.count;
    v.object_record = o.record.data();
    v.object_t1x = o.t1x.data(), v.object_t1y = o.t1y.data(), v.object_t1z = o.t1z.data();
    v.object_t2x = o.t2x.data(), v.object_t2y = o.t2y.data(), v.object_t2z = o.t2z.data();

    const CompiledMaterials& m = c.materials;
    v.mat_cd_r = m.cd_r.data(), v.mat_cd_g = m.cd_g.data(), v.mat_cd_b = m.cd_b.data();
    v.mat_kd = m.kd.data(), v.mat_ks = m.ks.data(), v.mat_shininess = m.shininess.data();
    v.mat_kr_r = m.kr_r.data(), v.mat_kr_g = m.kr_g.data(), v.mat_kr_b = m.kr_b.data();
    v.mat_kt = m.kt.data(), v.mat_ior = m.ior.data();
    v.mat_pow_zero_below = m.pow_zero_below.data();
    v.mat_checker_r = m.checker_r.data(), v.mat_checker_g = m.checker_g.data();
    v.mat_checker_b = m.checker_b.data(), v.mat_checker_size = m.checker_size.data();

    const CompiledLights& l = c.lights;
    v.light_count = l.count;
    v.light_directional = l.directional.data(),
    v.light_inverse_square = l.inverse_square.data();
    v.light_px = l.px.data(), v.light_py = l.py.data(), v.light_pz = l.pz.data();
    v.light_lx = l.lx.data(), v.light_ly = l.ly.data(), v.light_lz = l.lz.data();
    v.light_r = l.r.data(), v.light_g = l.g.data(), v.light_b = l.b.data();

    const CameraFrame& f = c.camera;
    v.camera = static_cast<kernels::CameraKind>(static_cast<int>(f.type));
    const auto put = [](float(&dst)[3], Vec3 a) { dst[0] = a.x, dst[1] = a.y, dst[2] = a.z; };
    const auto put_rgb = [](float(&dst)[3], Rgb a) {
        dst[0] = a.r, dst[1] = a.g, dst[2] = a.b;
    };
    put(v.eye, f.eye), put(v.ln, f.ln), put(v.u_hat, f.u_hat), put(v.v_hat, f.v_hat);
    put(v.u, f.u), put(v.v, f.v);
    v.aspect = f.aspect, v.half_width = f.half_width, v.half_height = f.half_height;
    v.half_fov_radians = f.half_fov_radians, v.aperture = f.aperture;
    v.focus_distance = f.focus_distance;

    v.background = c.background.type == BackgroundType::constant
                       ? kernels::BackgroundKind::constant
                       : kernels::BackgroundKind::gradient;
    put_rgb(v.bg_color, c.background.color), put_rgb(v.bg_bottom, c.background.bottom);
    put_rgb(v.bg_top, c.background.top), put(v.bg_up, c.background_up);
    put_rgb(v.ambient, c.ambient);
    v.epsilon = c.epsilon;
    v.max_depth = c.max_depth;
    v.shadow_cull_min_spheres = kShadowCullMinSpheres;
    return v;
}

double sphere_crossings(const float* r2, std::uint32_t count, const float lo[3],
                        const float hi[3]) {
    double area = 0.0;
    for (std::uint32_t i = 0; i < count; ++i) area += 4.0 * std::numbers::pi * r2[i];
    const double x = static_cast<double>(hi[0]) - lo[0], y = static_cast<double>(hi[1]) - lo[1],
                 z = static_cast<double>(hi[2]) - lo[2];
    const double box = 2.0 * (x * y + y * z + z * x);
    return box > 0.0 ? area / box : 0.0;
}

kernels::SceneView make_scene_view(const CompiledScene& scene, const SphereBvh& bvh,
                                   std::uint32_t packet_min_lanes,
                                   std::uint32_t secondary_min_lanes) {
    kernels::SceneView v = make_scene_view(scene);
    if (bvh.nodes.empty()) return v;
    v.bvh_nodes = bvh.nodes.data();
    v.bvh_cx = bvh.cx.data(), v.bvh_cy = bvh.cy.data(), v.bvh_cz = bvh.cz.data();
    v.bvh_r2 = bvh.r2.data(), v.bvh_object = bvh.object.data();
    for (int a = 0; a < 3; ++a) v.bvh_lo[a] = bvh.lo[a], v.bvh_hi[a] = bvh.hi[a];
    v.bvh_packet_min_lanes = packet_min_lanes;
    const std::uint32_t n = scene.spheres.count;
    const bool ray_by_ray = n >= kBvhSecondaryRayByRayMinSpheres ||
                            (n >= kBvhSecondaryRayByRayDenseMinSpheres &&
                             sphere_crossings(scene.spheres.r2.data(), n, bvh.lo, bvh.hi) >=
                                 kBvhSecondaryRayByRayMinCrossings);
    v.bvh_secondary_min_lanes = secondary_min_lanes != kBvhSecondaryLanesAuto
                                    ? secondary_min_lanes
                                : ray_by_ray ? kernels::kPacketWidth + 1
                                             : packet_min_lanes;
    v.bvh_shadow_sort_min_spheres = kBvhShadowSortMinSpheres;
    v.bvh_brute_force_max_spheres = kBvhBruteForceMaxSpheres;
    return v;
}

}  // namespace octray
