// `octray info [SCENE]`: what the CPU supports, which kernel ISAs this binary holds and
// which one the SIMD path will use; with a scene, its object counts, compile time and the
// sphere BVH (build time, memory per sphere, shape).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/accel.h"
#include "render/prepare/bvh_build.h"
#include "scene/compile.h"
#include "scene/load.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

void run_info(const std::string& scene_spec, bool quiet) {
    const CpuSupport cpu = cpu_support();
    std::printf("octray   %s\n", kVersion);
    std::printf("cpu      sse2 %s, sse4.1 %s, avx2 %s, fma %s, avx512 %s\n",
                cpu.sse2 ? "yes" : "no", cpu.sse4_1 ? "yes" : "no", cpu.avx2 ? "yes" : "no",
                cpu.fma ? "yes" : "no", cpu.avx512 ? "yes" : "no");
    std::string compiled, usable;
    for (Isa isa : compiled_isas()) {
        const kernels::KernelTable& k = kernel_table(isa);
        compiled +=
            std::string(compiled.empty() ? "" : ", ") + k.name + " (" +
            std::to_string(kernels::kPacketWidth / k.lanes_per_register) +
            (k.lanes_per_register == kernels::kPacketWidth ? " register" : " registers") +
            " per 8-ray packet" +
            (k.traversal_width == kernels::kPacketWidth
                 ? std::string()
                 : ", " + std::to_string(k.traversal_width) +
                       "-ray packets in BVH traversal and brute force") +
            ")";
    }
    for (Isa isa : supported_isas())
        usable += std::string(usable.empty() ? "" : ", ") + isa_name(isa);
    std::printf("kernels  %s\n", compiled.c_str());
    std::printf("usable   %s\n", usable.c_str());
    std::printf("uses     %s (--isa auto)\n", isa_name(resolve_isa(Isa::automatic)));
    if (scene_spec.empty()) return;

    const Scene scene = load_scene(scene_spec);
    print_scene_warnings(scene, quiet);
    const CompiledScene c = compile_scene(scene);
    std::printf("scene    %s: %dx%d, %d spp, max depth %d\n", scene_spec.c_str(),
                scene.image.width, scene.image.height, scene.image.spp, scene.render.max_depth);
    std::printf("objects  %u spheres (padded to %u), %u planes (padded to %u)\n",
                c.spheres.count, c.spheres.padded_count, c.planes.count, c.planes.padded_count);
    std::printf("         %u materials, %u lights, epsilon %g\n", c.materials.count,
                c.lights.count, static_cast<double>(c.epsilon));
    std::printf("compile  %.3f ms\n", c.compile_seconds * 1e3);
    if (c.spheres.count == 0) {
        std::printf("bvh      none (no spheres)\n");
        return;
    }
    // Built on every core, as `octray render` builds it.
    const SphereBvh bvh = build_sphere_bvh(c.spheres);
    std::printf("bvh      built in %.3f ms: %zu bytes, %.1f bytes/sphere\n",
                bvh.build_seconds * 1e3, bvh.memory_bytes(), bvh.bytes_per_sphere());
    std::printf("         %zu 8-wide nodes, %u leaves (%.2f spheres/leaf), depth %u\n",
                bvh.nodes.size(), bvh.leaf_count,
                static_cast<double>(bvh.sphere_count) / bvh.leaf_count, bvh.depth);
    std::printf("accel    --accel auto uses %s (the BVH from %u spheres on)\n",
                accel_uses_bvh(Accel::automatic, c.spheres.count) ? "the BVH" : "brute force",
                kBvhAutoMinSpheres);
}

}  // namespace

void add_info_command(CLI::App& app, CommandRunner& run) {
    auto scene = std::make_shared<std::string>();
    auto quiet = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand(
        "info",
        "Show the CPU's instruction sets and the kernels octray will use; with a "
        "scene, its object counts, compile time and sphere BVH (build time, bytes per "
        "sphere)");
    cmd->add_option("scene", *scene, "Optional scene: a JSON file or a built-in")
        ->type_name("SCENE")
        ->check(completes(builtin_scene_words()));
    cmd->footer(
        "Examples:\n"
        "  octray info                      # the CPU and the kernels --isa auto picks\n"
        "  octray info random:65536         # and the scene's counts and sphere BVH\n\n" +
        exit_code_help());
    cmd->add_flag("-q,--quiet", *quiet, kQuietHelp);
    cmd->callback(
        [scene, quiet, &run] { run.action = [scene, quiet] { run_info(*scene, *quiet); }; });
}

}  // namespace octray::tools
