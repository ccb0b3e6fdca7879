#include "view/view_switches.h"

#include <algorithm>

#include "kernels/dispatch.h"
#include "render/render_config.h"
#include "render/render_options.h"
#include "scene/max_depth.h"
#include "view/http_error.h"
#include "view/request_json.h"

namespace octray::view {
namespace {

using nlohmann::json;

std::string joined(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
    return out;
}

int integer(const json& value, const std::string& what, int lo, int hi) {
    if (!value.is_number_integer() || value.get<long long>() < lo ||
        value.get<long long>() > hi)
        throw BadRequest(400, "settings." + what + ": expected an integer in [" +
                                  std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(value.get<long long>());
}

// "auto" or an ISA of `limits`; a known ISA this CPU lacks is refused saying so.
Isa isa_from(const json& value, const SwitchLimits& limits) {
    const std::string choices = joined(isa_choices(limits));
    const std::optional<Isa> isa =
        value.is_string() ? parse_isa(value.get<std::string>()) : std::nullopt;
    if (!isa)
        throw BadRequest(
            400, "settings.isa: expected one of " + choices + ", found " + value.dump());
    if (*isa != Isa::automatic &&
        std::find(limits.isas.begin(), limits.isas.end(), *isa) == limits.isas.end())
        throw BadRequest(400, std::string("settings.isa: this CPU cannot run ") +
                                  isa_name(*isa) + " (it runs " + choices + ")");
    return *isa;
}

}  // namespace

SwitchLimits switch_limits(const ViewSession& session) {
    return SwitchLimits{supported_isas(), session.frame_count()};
}

std::vector<std::string> isa_choices(const SwitchLimits& limits) {
    std::vector<std::string> names{isa_name(Isa::automatic)};
    for (const Isa isa : limits.isas) names.emplace_back(isa_name(isa));
    return names;
}

RenderSwitches parse_switches(const std::string& body, RenderSwitches switches,
                              const SwitchLimits& limits) {
    const json request = parse_request_json(body, "settings");
    if (request.is_discarded() || !request.is_object())
        throw BadRequest(400, "settings: expected a JSON object such as {\"spp\": 16}");
    for (const auto& [key, value] : request.items()) {
        if (key == "threads") {
            switches.render.threads = integer(value, key, 0, kMaxRenderThreads);
        } else if (key == "spp") {
            switches.spp = integer(value, key, 1, kMaxSamplesPerPixel);
        } else if (key == "max_depth") {
            switches.max_depth = integer(value, key, 1, kMaxDepthLimit);
        } else if (key == "order") {
            const auto order =
                value.is_string() ? parse_pixel_order(value.get<std::string>()) : std::nullopt;
            if (!order)
                throw BadRequest(400, "settings.order: expected tiled, rows or frameless");
            switches.order = *order;
        } else if (key == "path") {
            try {  // the command line's parser and message (RenderConfig::set_path)
                switches.render.set_path(value.is_string() ? value.get<std::string>()
                                                           : value.dump());
            } catch (const ConfigError& e) {
                throw BadRequest(400, "settings.path: " + e.detail());
            }
        } else if (key == "isa") {
            switches.render.isa = isa_from(value, limits);
        } else if (key == "frame") {
            if (limits.frames <= 1 && value.is_number_integer() && value.get<long long>() != 0)
                throw BadRequest(400,
                                 "settings.frame: the scene is not animated (frame 0 only)");
            switches.frame = integer(value, key, 0, std::max(1, limits.frames) - 1);
        } else {
            throw BadRequest(400, "settings: unknown key \"" + key +
                                      "\" (expected threads, spp, max_depth, order, path, isa, "
                                      "frame)");
        }
    }
    return switches;
}

std::string path_label(RenderPath path, Isa isa) {
    RenderConfig config;
    config.path = path;
    config.isa = isa;
    config.resolve_isa();
    return config.path_label();
}

json switches_json(const RenderSwitches& switches) {
    return json{{"threads", switches.render.threads},
                {"spp", switches.spp},
                {"max_depth", switches.max_depth},
                {"order", to_string(switches.order)},
                {"path", render_path_name(switches.render.path)},
                {"isa", isa_name(switches.render.isa)},
                {"frame", switches.frame}};
}

}  // namespace octray::view
