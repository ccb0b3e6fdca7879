#include "view/view_server.h"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <utility>

#include "core/decimal.h"
#include "render/image/image_io.h"
#include "scene/load.h"
#include "scene/scene_error.h"
#include "view/guarded_server.h"
#include "view/http_error.h"
#include "view/jpeg.h"
#include "view/page.h"
#include "view/request_json.h"
#include "view/token.h"
#include "view/tone_map.h"
#include "view/view_save.h"
#include "view/view_switches.h"

namespace octray::view {
namespace {

using nlohmann::json;

// How often an idle event stream writes a comment line: the write that fails tells the
// server a tab has closed, so the stream's worker thread is back within about this long.
constexpr std::chrono::milliseconds kHeartbeat{250};

json vec3_json(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

json frame_json(const ViewFrame& frame) {
    const Camera& camera = frame.camera;
    return json{
        {"generation", frame.generation},
        {"camera_version", frame.camera_version},
        {"preview", frame.preview},
        {"spp", frame.spp},
        {"target_spp", frame.target_spp},
        {"width", frame.image.width()},
        {"height", frame.image.height()},
        {"pass_seconds", frame.pass_seconds},
        {"frame_seconds", frame.frame_seconds},
        {"mrays_per_second", frame.mrays_per_second},
        {"coverage", frame.coverage},
        {"animation_frame", frame.animation_frame},
        {"path", path_label(frame.path, frame.isa)},
        {"camera",
         {{"eye", vec3_json(camera.eye)},
          {"lookat", vec3_json(camera.lookat)},
          {"up", vec3_json(camera.up)},
          {"fov", camera.fov}}},
    };
}

float finite_number(const json& value, const std::string& what) {
    if (!value.is_number()) throw BadRequest(400, what + ": expected a number");
    const double v = value.get<double>();
    if (!std::isfinite(v) || std::fabs(v) > 1e30)
        throw BadRequest(400, what + ": expected a finite number of at most 1e30");
    return static_cast<float>(v);
}

Vec3 vec3_from(const json& value, const std::string& what) {
    if (!value.is_array() || value.size() != 3)
        throw BadRequest(400, what + ": expected an array of 3 numbers");
    return Vec3{finite_number(value[0], what + "[0]"), finite_number(value[1], what + "[1]"),
                finite_number(value[2], what + "[2]")};
}

// The body of POST /api/camera: {"eye": [x, y, z], "lookat": [...], "up": [...],
// "fov": degrees, "moving": bool}, every key optional (the current camera's value).
std::pair<Camera, bool> parse_camera_request(const std::string& body, Camera camera) {
    const json request = parse_request_json(body, "camera");
    if (request.is_discarded() || !request.is_object())
        throw BadRequest(400, "camera: expected a JSON object such as {\"eye\": [0, 1, 5]}");
    bool moving = false;
    for (const auto& [key, value] : request.items()) {
        if (key == "eye") {
            camera.eye = vec3_from(value, "camera.eye");
        } else if (key == "lookat") {
            camera.lookat = vec3_from(value, "camera.lookat");
        } else if (key == "up") {
            camera.up = vec3_from(value, "camera.up");
        } else if (key == "fov") {
            camera.fov = finite_number(value, "camera.fov");
        } else if (key == "moving") {
            if (!value.is_boolean())
                throw BadRequest(400, "camera.moving: expected true or false");
            moving = value.get<bool>();
        } else {
            throw BadRequest(400, "camera: unknown key \"" + key +
                                      "\" (expected eye, lookat, up, fov, moving)");
        }
    }
    return {camera, moving};
}

// The value of cookie `name` in a Cookie header ("a=1; b=2"), empty if absent.
std::string cookie_value(const std::string& header, const std::string& name) {
    std::size_t pos = 0;
    while (pos < header.size()) {
        while (pos < header.size() && (header[pos] == ' ' || header[pos] == ';')) ++pos;
        const std::size_t end = std::min(header.find(';', pos), header.size());
        const std::string pair = header.substr(pos, end - pos);
        const std::size_t eq = pair.find('=');
        if (eq != std::string::npos && pair.compare(0, eq, name) == 0)
            return pair.substr(eq + 1);
        pos = end;
    }
    return {};
}

// Query parameter `name` as an integer in [lo, hi]; 400 naming it otherwise.
int integer_param(const httplib::Request& req, const std::string& name, int lo, int hi) {
    if (!req.has_param(name))
        throw BadRequest(400, name + ": missing (expected an integer in [" +
                                  std::to_string(lo) + ", " + std::to_string(hi) + "])");
    // Decimal digits only, as the command line and scene files: no sign, blank or prefix.
    const std::string text = req.get_param_value(name);
    const std::optional<std::uint64_t> value = parse_decimal_digits(text);
    if (!value || *value < static_cast<std::uint64_t>(std::max(lo, 0)) ||
        *value > static_cast<std::uint64_t>(hi) || hi < 0)
        throw BadRequest(400, name + ": expected an integer in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "], found \"" + text + "\"");
    return static_cast<int>(*value);
}

// The `exposure` query parameter: stops in [-64, 64], default 0.
float exposure_param(const httplib::Request& req) {
    if (!req.has_param("exposure")) return 0.0f;
    const std::string text = req.get_param_value("exposure");
    char* end = nullptr;
    const float value = std::strtof(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value) || std::fabs(value) > 64)
        throw BadRequest(400, "exposure: expected a number of stops in [-64, 64]");
    return value;
}

// {"x": X, "y": Y, "width": W, "height": H, "rgb": [r, g, b]}: the linear value of pixel
// (x, y) of `image` (non-finite values as the strings "nan", "inf", "-inf").
json pixel_json(const httplib::Request& req, const Image& image) {
    const int x = integer_param(req, "x", 0, image.width() - 1);
    const int y = integer_param(req, "y", 0, image.height() - 1);
    const Rgb p = rgb_at(image, x, y);
    const auto value = [](float v) -> json {
        if (std::isnan(v)) return "nan";
        if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
        return v;
    };
    return json{{"x", x},
                {"y", y},
                {"width", image.width()},
                {"height", image.height()},
                {"rgb", json::array({value(p.r), value(p.g), value(p.b)})}};
}

// The picture's floats interleaved, r g b per pixel, row 0 first (what the page reads).
std::string float_bytes(const Image& image) {
    const std::size_t n = image.pixel_count();
    std::vector<float> rgb(3 * n);
    for (int c = 0; c < 3; ++c) {
        const float* plane = image.plane(c);
        for (std::size_t i = 0; i < n; ++i) rgb[3 * i + static_cast<std::size_t>(c)] = plane[i];
    }
    return std::string(reinterpret_cast<const char*>(rgb.data()), rgb.size() * sizeof(float));
}

// One message of /api/pictures: "OCTP", the lengths of `header` and `picture` (uint32,
// little-endian), then both.
std::string picture_message(const std::string& header, const std::string& picture) {
    std::string message = "OCTP";
    for (const std::size_t length : {header.size(), picture.size()}) {
        for (int byte = 0; byte < 4; ++byte)
            message.push_back(static_cast<char>((length >> (8 * byte)) & 0xff));
    }
    return message + header + picture;
}

// `frame` as a message of /api/pictures (encode_for_page: PNG once refined, else JPEG).
std::string encoded_picture(const ViewFrame& frame, float exposure) {
    PagePicture picture = encode_for_page(frame, exposure);
    json header = frame_json(frame);
    header["event"] = "frame";
    header["format"] = picture.format;
    header["exposure"] = exposure;
    return picture_message(header.dump(), picture.bytes);
}

void set_common_headers(httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Referrer-Policy", "no-referrer");
}

}  // namespace

struct ViewServer::Impl {
    ViewSession* session_ptr;        // a scene, or
    const CompareView* compare_ptr;  // two images (`octray view A.exr B.exr`)
    ServerOptions options;
    std::string token;
    std::string cookie_name;
    int port = 0;
    GuardedServer server;
    std::thread listener;
    std::atomic<bool> stopping{false};
    std::atomic<bool> listener_done{false};
    // `octray view A B`: the pictures of layers other than the colour, by (picture, layer),
    // made when first asked for (std::map: references to them stay valid).
    std::mutex layer_mutex;
    std::map<std::pair<std::string, std::string>, Image> layer_pictures;
    std::mutex stop_mutex;

    Impl(ViewSession* s, const CompareView* c, ServerOptions o)
        : session_ptr(s),
          compare_ptr(c),
          options(std::move(o)),
          server(ConnectionLimits{options.max_connections, options.auth_deadline}) {
        token = options.token.empty() ? random_token() : options.token;
    }

    bool authorized(const httplib::Request& req) const {
        if (req.has_param("token") && tokens_equal(req.get_param_value("token"), token))
            return true;
        return tokens_equal(cookie_value(req.get_header_value("Cookie"), cookie_name), token);
    }

    void routes();
    void scene_routes();
    void compare_routes();
};

void ViewServer::Impl::routes() {
    server.set_payload_max_length(options.max_body);
    server.set_tcp_nodelay(true);
    server.set_keep_alive_timeout(2);
    server.set_read_timeout(5, 0);
    server.set_write_timeout(5, 0);
    // Each connection is served on a thread of its own, at most max_connections at once
    // (GuardedServer), so an open event stream holds no worker the page and the API need.

    // The token first: nothing, not even a 404, answers a request without it.
    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
        set_common_headers(res);
        if (authorized(req)) {
            // This connection is no longer held to the deadline for presenting the token.
            GuardedServer::mark_authenticated();
            return httplib::Server::HandlerResponse::Unhandled;
        }
        res.status = 403;
        res.set_content(
            "403 Forbidden: open the URL that `octray view` printed (it carries the token)\n",
            "text/plain");
        return httplib::Server::HandlerResponse::Handled;
    });
    server.set_exception_handler([](const httplib::Request&, httplib::Response& res,
                                    std::exception_ptr error) {
        try {
            std::rethrow_exception(error);
        } catch (const BadRequest& e) {
            res.status = e.status;
            res.set_content(std::string(e.what()) + "\n", "text/plain");
        } catch (const SceneError& e) {
            res.status = 400;
            res.set_content(std::string(e.what()) + "\n", "text/plain");
        } catch (const IoError& e) {
            // A file save could not write (a full disk, a read-only directory): not a bug.
            res.status = 500;
            res.set_content(std::string(e.what()) + "\n", "text/plain");
        } catch (const std::exception& e) {
            res.status = 500;
            res.set_content(std::string("internal error: ") + e.what() + "\n", "text/plain");
        }
    });

    server.Get("/", [this](const httplib::Request&, httplib::Response& res) {
        // The cookie lets the page's requests carry the token without repeating it; its
        // name has the port in it because cookies do not tell ports apart.
        res.set_header("Set-Cookie",
                       cookie_name + "=" + token + "; Path=/; HttpOnly; SameSite=Strict");
        res.set_content(kViewPage, "text/html; charset=utf-8");
    });

    if (session_ptr != nullptr)
        scene_routes();
    else
        compare_routes();
}

void ViewServer::Impl::scene_routes() {
    ViewSession& session = *session_ptr;
    server.Get("/api/status", [&session](const httplib::Request&, httplib::Response& res) {
        const Scene scene = session.scene();
        json status{{"mode", "scene"},
                    {"scene", scene.source},
                    {"full_width", scene.image.width},
                    {"full_height", scene.image.height},
                    {"settings", switches_json(session.switches())},
                    {"isas", isa_choices(switch_limits(session))},
                    {"animation", nullptr}};
        if (session.frame_count() > 1)
            status["animation"] = {{"frames", session.frame_count()},
                                   {"fps", session.frames_per_second()}};
        if (const auto frame = session.latest()) status["frame"] = frame_json(*frame);
        if (const std::string error = session.error(); !error.empty()) status["error"] = error;
        res.set_content(status.dump(), "application/json");
    });

    server.Get(
        "/api/events", [this, &session](const httplib::Request&, httplib::Response& res) {
            res.set_chunked_content_provider(
                "text/event-stream",
                [this, &session, last = std::uint64_t{0}, last_error = std::string()](
                    std::size_t, httplib::DataSink& sink) mutable {
                    const auto frame = session.wait_newer(last, kHeartbeat);
                    if (stopping || session.stopped()) {
                        sink.done();
                        return true;
                    }
                    std::string message = ": heartbeat\n\n";
                    if (std::string error = session.error(); error != last_error) {
                        last_error = error;
                        if (!error.empty()) {
                            message = "event: render-error\ndata: " +
                                      json{{"message", error}}.dump() + "\n\n";
                        }
                    } else if (frame && frame->generation > last) {
                        last = frame->generation;
                        message = "event: frame\ndata: " + frame_json(*frame).dump() + "\n\n";
                    }
                    return sink.write(message.data(), message.size());
                });
        });

    // The pictures themselves, pushed (issue 44): one long-lived chunked response of
    // messages, each "OCTP", the length of a JSON header and the length of a picture
    // (uint32, little-endian), the JSON (the event's frame JSON with "event": "frame" and
    // "format": "jpeg" or "png"; or "event": "render-error" with "message") and the
    // picture's file bytes. Lengths of 0 and 0: a heartbeat. The latest picture wins: the
    // stream encodes and writes the newest picture once the last one is written, so a
    // slow browser skips pictures and nothing queues; the render thread goes on with the
    // next picture meanwhile. Previews and the passes before the last are JPEG (a few
    // milliseconds to encode and to decode at 1280x720; PNG costs several times that),
    // the refined picture PNG, lossless.
    server.Get(
        "/api/pictures", [this, &session](const httplib::Request& req, httplib::Response& res) {
            const float exposure = exposure_param(req);
            res.set_chunked_content_provider(
                "application/octet-stream",
                [this, &session, exposure, last = std::uint64_t{0}, last_error = std::string()](
                    std::size_t, httplib::DataSink& sink) mutable {
                    const auto frame = session.wait_newer(last, kHeartbeat);
                    if (stopping || session.stopped()) {
                        sink.done();
                        return true;
                    }
                    std::string message = picture_message(std::string(), std::string());
                    if (std::string error = session.error(); error != last_error) {
                        last_error = error;
                        if (!error.empty())
                            message = picture_message(
                                json{{"event", "render-error"}, {"message", error}}.dump(), {});
                    } else if (frame && frame->generation > last) {
                        last = frame->generation;
                        message = encoded_picture(*frame, exposure);
                    }
                    return sink.write(message.data(), message.size());
                });
        });

    const auto image_headers = [](httplib::Response& res, const ViewFrame& frame) {
        res.set_header("X-Octray-Generation", std::to_string(frame.generation));
        res.set_header("X-Octray-Spp", std::to_string(frame.spp));
        res.set_header("X-Octray-Width", std::to_string(frame.image.width()));
        res.set_header("X-Octray-Height", std::to_string(frame.image.height()));
        res.set_header("X-Octray-Camera-Version", std::to_string(frame.camera_version));
    };

    server.Get("/api/image.png",
               [&session, image_headers](const httplib::Request& req, httplib::Response& res) {
                   const auto frame = session.latest();
                   if (!frame) throw BadRequest(503, "no picture yet");
                   const float exposure = exposure_param(req);
                   image_headers(res, *frame);
                   res.set_content(encode_png_rgb8(frame->image.width(), frame->image.height(),
                                                   tone_map_srgb8(frame->image, exposure)),
                                   "image/png");
               });

    // The picture as it is: little-endian float32 R, G, B per pixel, row 0 on top, for
    // tests and tools that compare exactly.
    server.Get("/api/image.f32",
               [&session, image_headers](const httplib::Request&, httplib::Response& res) {
                   const auto frame = session.latest();
                   if (!frame) throw BadRequest(503, "no picture yet");
                   image_headers(res, *frame);
                   res.set_content(float_bytes(frame->image), "application/octet-stream");
               });

    // The linear value under the page's cursor, of the latest picture (whose size the
    // answer repeats: a preview is smaller than the refined picture).
    // `width` and `height`, when given, are the size of the picture the page shows, in
    // which x and y are: a page that still shows a preview while the refined picture is
    // in (or the other way round) is answered the pixel at the same place of the latest.
    server.Get("/api/pixel", [&session](const httplib::Request& req, httplib::Response& res) {
        const auto frame = session.latest();
        if (!frame) throw BadRequest(503, "no picture yet");
        json answer;
        if (req.has_param("width") || req.has_param("height")) {
            const int shown_w = integer_param(req, "width", 1, 1 << 16);
            const int shown_h = integer_param(req, "height", 1, 1 << 16);
            const int x = integer_param(req, "x", 0, shown_w - 1);
            const int y = integer_param(req, "y", 0, shown_h - 1);
            const int w = frame->image.width(), h = frame->image.height();
            httplib::Request at;
            at.params = {
                {"x", std::to_string(static_cast<int>(
                          (static_cast<std::int64_t>(2 * x + 1) * w) / (2 * shown_w)))},
                {"y", std::to_string(static_cast<int>(
                          (static_cast<std::int64_t>(2 * y + 1) * h) / (2 * shown_h)))}};
            answer = pixel_json(at, frame->image);
        } else {
            answer = pixel_json(req, frame->image);
        }
        answer["generation"] = frame->generation;
        res.set_content(answer.dump(), "application/json");
    });

    if (options.save) {
        server.Post("/api/save",
                    [this, &session](const httplib::Request& req, httplib::Response& res) {
                        res.set_content(save_view(session, *options.save, req.body).dump(),
                                        "application/json");
                    });
    }

    // The page's switches (view_switches.h); a change re-renders the current camera, as a
    // new camera version: the pictures made with the new switches carry it.
    server.Post("/api/settings",
                [&session](const httplib::Request& req, httplib::Response& res) {
                    const std::uint64_t version = session.reconfigure(
                        parse_switches(req.body, session.switches(), switch_limits(session)));
                    res.set_content(json{{"ok", true}, {"camera_version", version}}.dump(),
                                    "application/json");
                });

    server.Post("/api/camera", [&session](const httplib::Request& req, httplib::Response& res) {
        const auto [camera, moving] = parse_camera_request(req.body, session.camera());
        const std::uint64_t version = session.set_camera(camera, moving);
        res.set_content(json{{"camera_version", version}}.dump(), "application/json");
    });
}

void ViewServer::Impl::compare_routes() {
    const CompareView& view = *compare_ptr;
    server.Get("/api/status", [&view](const httplib::Request&, httplib::Response& res) {
        const json status{{"mode", "compare"},
                          {"a", view.path_a},
                          {"b", view.path_b},
                          {"full_width", view.result.width},
                          {"full_height", view.result.height},
                          {"heatmap_width", view.heatmap.image.width()},
                          {"heatmap_height", view.heatmap.image.height()},
                          {"heatmap_zoom", view.heatmap.zoom},
                          {"heatmap_legend", view.heatmap.legend},
                          {"heatmap_min", view.heatmap.scale_min},
                          {"heatmap_max", view.heatmap.scale_max},
                          {"layers", view.layers},
                          {"compare", json::parse(view.figures_json)}};
        res.set_content(status.dump(), "application/json");
    });
    // Exactly what `octray compare --json A B` prints.
    server.Get("/api/compare", [&view](const httplib::Request&, httplib::Response& res) {
        res.set_content(view.figures_json, "application/json");
    });
    // picture=a (default), b or diff: the linear RGB picture; layer= one of the status's
    // layers (default "": the colour), each made once when first asked for.
    const auto picture = [this, &view](const httplib::Request& req) -> const Image& {
        const std::string name =
            req.has_param("picture") ? req.get_param_value("picture") : "a";
        const std::string layer = req.has_param("layer") ? req.get_param_value("layer") : "";
        if (std::find(view.layers.begin(), view.layers.end(), layer) == view.layers.end()) {
            std::string known;
            for (const std::string& l : view.layers)
                known += (known.empty() ? "\"" : ", \"") + l + "\"";
            throw BadRequest(400,
                             "layer: expected one of " + known + ", found \"" + layer + "\"");
        }
        if (!layer.empty() && (name == "a" || name == "b" || name == "diff")) {
            const std::lock_guard lock(layer_mutex);
            auto [it, fresh] = layer_pictures.try_emplace({name, layer});
            if (fresh) {
                const Image& source = name == "a" ? view.a : name == "b" ? view.b : view.diff;
                it->second = display_rgb(source, layer);
            }
            return it->second;
        }
        if (name == "a") return view.rgb_a;
        if (name == "b") return view.rgb_b;
        if (name == "diff") return view.rgb_diff;
        // (The heatmap is answered before this, and only as a PNG.)
        if (name == "heatmap")
            throw BadRequest(400,
                             "picture: the heatmap is a PNG picture only (/api/image.png?"
                             "picture=heatmap); here expected a, b or diff");
        throw BadRequest(
            400, "picture: expected a, b, diff or heatmap (PNG only), found \"" + name + "\"");
    };
    server.Get("/api/image.png", [&view, picture](const httplib::Request& req,
                                                  httplib::Response& res) {
        const float exposure = exposure_param(req);
        if (req.has_param("picture") && req.get_param_value("picture") == "heatmap") {
            res.set_content(encode_png(view.heatmap.image), "image/png");
            return;
        }
        const Image& image = picture(req);
        res.set_content(
            encode_png_rgb8(image.width(), image.height(), tone_map_srgb8(image, exposure)),
            "image/png");
    });
    server.Get("/api/image.f32",
               [picture](const httplib::Request& req, httplib::Response& res) {
                   const Image& image = picture(req);
                   res.set_header("X-Octray-Width", std::to_string(image.width()));
                   res.set_header("X-Octray-Height", std::to_string(image.height()));
                   res.set_content(float_bytes(image), "application/octet-stream");
               });
    server.Get("/api/pixel", [picture](const httplib::Request& req, httplib::Response& res) {
        res.set_content(pixel_json(req, picture(req)).dump(), "application/json");
    });
}

ViewServer::ViewServer(ViewSession& session, ServerOptions options)
    : ViewServer(std::make_unique<Impl>(&session, nullptr, std::move(options))) {}

ViewServer::ViewServer(const CompareView& images, ServerOptions options)
    : ViewServer(std::make_unique<Impl>(nullptr, &images, std::move(options))) {}

ViewServer::ViewServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {
    impl_->routes();
    const std::string& host = impl_->options.bind;
    const auto failure = [&](int port) {
        const int error = errno;
        return std::runtime_error("cannot listen on " + host + ":" + std::to_string(port) +
                                  (error != 0 ? std::string(": ") + std::strerror(error) : ""));
    };
    errno = 0;
    if (impl_->options.port == 0) {
        impl_->port = impl_->server.bind_to_any_port(host);
        if (impl_->port <= 0) throw failure(0);
    } else {
        if (!impl_->server.bind_to_port(host, impl_->options.port))
            throw failure(impl_->options.port);
        impl_->port = impl_->options.port;
    }
    impl_->cookie_name = "octray_token_" + std::to_string(impl_->port);
}

ViewServer::~ViewServer() {
    stop();
    wait();
}

void ViewServer::start() {
    if (impl_->stopping) return;
    std::signal(SIGPIPE, SIG_IGN);
    impl_->listener = std::thread([this] {
        impl_->server.listen_after_bind();
        impl_->listener_done = true;
    });
    // stop() before listen_after_bind() runs would be lost: wait until it does.
    while (!impl_->server.is_running() && !impl_->stopping && !impl_->listener_done)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void ViewServer::stop() {
    std::lock_guard lock(impl_->stop_mutex);
    impl_->stopping = true;
    impl_->server.stop();
    // Idle keep-alive connections and unfinished requests end now, not at their timeouts.
    impl_->server.end_connections();
}

void ViewServer::wait() {
    if (impl_->listener.joinable()) impl_->listener.join();
}

int ViewServer::port() const { return impl_->port; }

const std::string& ViewServer::token() const { return impl_->token; }

std::string ViewServer::url() const {
    std::string host = impl_->options.bind;
    if (host.find(':') != std::string::npos) host = "[" + host + "]";
    return "http://" + host + ":" + std::to_string(impl_->port) + "/?token=" + impl_->token;
}

}  // namespace octray::view
