#pragma once
// POST /api/settings of `octray view` (view/README.md): the page's switches —
// threads, spp, max depth, pixel order, render path, ISA and the animation's frame — read
// from the request's JSON and checked, and the JSON in which /api/status reports them.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kernels/isa.h"
#include "render/render_options.h"
#include "view/view_session.h"

namespace octray::view {

// What the switches may be set to beyond their fixed ranges.
struct SwitchLimits {
    std::vector<Isa> isas;  // the ISAs this CPU runs (supported_isas()); "auto" always
    int frames = 1;         // the animation's frame count (1: a still scene, frame 0 only)
};

// The limits of `session`'s switches on this CPU.
SwitchLimits switch_limits(const ViewSession& session);

// The ISA names the page offers: "auto", then `limits.isas`.
std::vector<std::string> isa_choices(const SwitchLimits& limits);

// `current` with the body of POST /api/settings applied: {"threads": 0..4096, "spp":
// 1..2^20, "max_depth": 1..64, "order": "tiled" | "rows" | "frameless", "path": "simd" |
// "scalar", "isa": "auto" | one of limits.isas, "frame": 0..frames-1}, every key
// optional. Anything else — not JSON, an unknown key, a wrong type, a value out of range,
// an ISA this CPU lacks — throws BadRequest (view/http_error.h) with status 400 and
// a message naming the key and what it takes.
RenderSwitches parse_switches(const std::string& body, RenderSwitches current,
                              const SwitchLimits& limits);

// What made a picture, as `octray render` names it in its header (octray.path): "scalar",
// or "simd (ISA)" with an automatic ISA resolved to this CPU's best.
std::string path_label(RenderPath path, Isa isa);

// {"threads", "spp", "max_depth", "order", "path", "isa", "frame"}: /api/status's
// "settings".
nlohmann::json switches_json(const RenderSwitches& switches);

}  // namespace octray::view
