#pragma once
// The HTTP side of `octray view`: the page, the pictures of a ViewSession and the camera
// endpoint, behind an access token (view/README.md lists the protocol).

#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "view/compare_view.h"
#include "view/view_session.h"

namespace octray::view {

// What POST /api/save needs to write the current picture as `octray render` would: the
// scene's identity for the EXR header and for the command line that renders it again (the
// picture itself says which path and ISA made it, the session which frame it is).
struct SaveSettings {
    std::string spec;             // the scene as given on the command line (octray.scene)
    std::string sha256;           // its digest (octray.sceneSha256)
    std::string directory = ".";  // where files are written: the working directory
};

struct ServerOptions {
    std::string bind = "127.0.0.1";  // loopback only unless the user says otherwise
    int port = 0;                    // 0: a free port, chosen by the kernel
    std::string token;               // empty: random_token()
    std::size_t max_body = 4096;     // bytes; a longer request body gets 413
    // Connections open at once, event streams included (each is served on a thread of its
    // own); one more is answered 503 saying so, then closed.
    int max_connections = 256;
    // A connection that has not presented the token this long after it opened is closed,
    // however slowly it trickles its bytes.
    std::chrono::milliseconds auth_deadline{5000};
    std::optional<SaveSettings> save;  // absent: no /api/save
};

class ViewServer {
  public:
    // Binds the socket (nothing is served before start()). Throws std::runtime_error
    // naming the address if it cannot be bound. `session` must outlive the server.
    ViewServer(ViewSession& session, ServerOptions options);
    // `octray view A.exr B.exr`: serves the two images, their difference, the heatmap and
    // the figures of `images` (no renderer, no camera). `images` must outlive the server.
    ViewServer(const CompareView& images, ServerOptions options);
    ~ViewServer();  // stop()
    ViewServer(const ViewServer&) = delete;
    ViewServer& operator=(const ViewServer&) = delete;

    // Serves on a thread of its own until stop(); returns once requests are accepted.
    // Ignores SIGPIPE for the whole process: a client that goes away mid-answer must give
    // a failed write, not kill the viewer.
    void start();
    // Stops accepting, ends the event streams and waits for the requests in flight.
    // Safe to call from any thread, more than once.
    void stop();
    // Blocks until the server has stopped (after stop(), from another thread or a signal).
    void wait();

    int port() const;
    const std::string& token() const;
    // http://HOST:PORT/?token=TOKEN — what the user opens.
    std::string url() const;

  private:
    struct Impl;
    explicit ViewServer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace octray::view
