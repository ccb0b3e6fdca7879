#pragma once
// An httplib::Server that stays responsive under load (issue 38): every connection is served
// on a thread of its own (no fixed pool, so a long-lived event stream holds no worker that
// the page and the API need), the number of connections is capped (past it a client gets
// a 503 saying so, then the connection closes), and a connection that has not presented
// the token within a deadline of its opening is shut down, however slowly it trickles its
// bytes (view/README.md, "Safety").
//
// It replaces httplib's private virtual `process_and_close_socket` (legal C++: a derived
// class may override a private virtual) with its own keep-alive loop around the protected
// `process_request`, over a socket stream of its own: Debian's httplib is a compiled
// library whose header declares neither `detail::process_server_socket` nor its
// `SocketStream`.

#include <httplib.h>

#include <chrono>
#include <cstddef>
#include <memory>

namespace octray::view {

struct ConnectionLimits {
    // Connections open at once (event streams included); one more gets a 503.
    int max_connections = 256;
    // A connection must present the token (mark_authenticated) within this time of being
    // accepted, or it is shut down.
    std::chrono::milliseconds auth_deadline{5000};
};

class GuardedServer : public httplib::Server {
  public:
    explicit GuardedServer(ConnectionLimits limits);
    ~GuardedServer() override;
    GuardedServer(const GuardedServer&) = delete;
    GuardedServer& operator=(const GuardedServer&) = delete;

    // Marks the connection whose request the calling thread serves as authenticated (the
    // deadline no longer applies to it). Call it from a handler, e.g. the pre-routing one.
    static void mark_authenticated();

    // After stop(): ends the reading side of every open connection, so that idle
    // keep-alive connections and unfinished requests end now rather than at their timeouts
    // (answers being written still finish).
    void end_connections();

    const ConnectionLimits& limits() const;

    struct State;

  private:
    bool process_and_close_socket(socket_t sock) override;

    std::shared_ptr<State> state_;
};

}  // namespace octray::view
