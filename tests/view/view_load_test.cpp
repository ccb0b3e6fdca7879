// Issue 38: `octray view` stays responsive under load. Before, the server ran every
// connection on a fixed pool of 16 workers: 16 open event streams, or 16 clients trickling
// a request a byte at a time without the token, left no worker for the page and the API.
// Now each connection has a thread of its own (view/guarded_server.h), connections
// that do not present the token within a deadline are closed, and past a cap on
// connections the answer is a 503 saying so. The clients here are raw sockets, so that
// hundreds of them cost the test one thread.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "view/view_server.h"
#include "view/view_session.h"
#include "view_fixtures.h"

namespace {

using Clock = std::chrono::steady_clock;
using octray::view::ServerOptions;
using octray::view::ViewServer;
using octray::view::ViewSession;
using octray::view::ViewSettings;

// A socket connected to the server; -1 if it could not connect.
int connect_to(int port) {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

bool send_text(int fd, const std::string& text) {
    return send(fd, text.data(), text.size(), MSG_NOSIGNAL) ==
           static_cast<ssize_t>(text.size());
}

// Reads from `fd` until what was read contains `text`, the peer closes, or `timeout` runs
// out; what was read.
std::string read_until(int fd, const std::string& text, std::chrono::milliseconds timeout) {
    std::string got;
    const auto until = Clock::now() + timeout;
    while (got.find(text) == std::string::npos && Clock::now() < until) {
        pollfd p{fd, POLLIN, 0};
        if (poll(&p, 1, 50) <= 0) continue;
        char buffer[4096];
        const ssize_t n = recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        got.append(buffer, static_cast<std::size_t>(n));
    }
    return got;
}

// True once the server has closed `fd` (a read gives end of file or an error).
bool closed_by_server(int fd) {
    for (;;) {
        pollfd p{fd, POLLIN, 0};
        if (poll(&p, 1, 0) <= 0) return false;
        char buffer[4096];
        const ssize_t n = recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
        if (n <= 0) return true;
    }
}

class ViewLoadTest : public ::testing::Test {
  protected:
    void start(ServerOptions options) {
        ViewSettings settings;
        settings.render.threads = 2;
        session_ = std::make_unique<ViewSession>(scene_, settings);
        server_ = std::make_unique<ViewServer>(*session_, std::move(options));
        server_->start();
    }
    void TearDown() override {
        server_.reset();
        session_.reset();
    }

    std::string request(const std::string& path, bool token = true) const {
        return "GET " + path + (token ? "?token=" + server_->token() : "") +
               " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
    }

    // GET /api/status with the token on a new connection, waiting up to 10 s for it.
    int status_code() const {
        httplib::Client client("127.0.0.1", server_->port());
        client.set_connection_timeout(10, 0);
        client.set_read_timeout(10, 0);
        const auto result = client.Get("/api/status?token=" + server_->token());
        return result ? result->status : -1;
    }

    // An event stream on a raw socket that has announced the current picture; -1 if the
    // stream did not open.
    int open_stream() const {
        const int fd = connect_to(server_->port());
        if (fd < 0) return -1;
        const std::string head = request("/api/events");
        const std::string got = send_text(fd, head)
                                    ? read_until(fd, "event: frame", std::chrono::seconds(10))
                                    : std::string();
        if (got.rfind("HTTP/1.1 200", 0) != 0 ||
            got.find("event: frame") == std::string::npos) {
            close(fd);
            return -1;
        }
        return fd;
    }

    const octray::Scene scene_ = octray::view::testing::small_whitted();
    std::unique_ptr<ViewSession> session_;
    std::unique_ptr<ViewServer> server_;
};

// 200 event streams open at once (tabs, or a client opening many): every one opens and
// announces the picture, and the page and the API still answer. Before, streams past 8
// were refused and 16 left /api/status hanging.
TEST_F(ViewLoadTest, TwoHundredEventStreamsLeaveThePageAndTheApiAnswering) {
    start(ServerOptions{});
    std::vector<int> streams;
    for (int i = 0; i < 200; ++i) {
        const int fd = open_stream();
        if (fd < 0) break;
        streams.push_back(fd);
    }
    EXPECT_EQ(streams.size(), 200u) << "event stream " << streams.size() << " did not open";
    EXPECT_EQ(status_code(), 200) << "the API did not answer with the streams open";
    httplib::Client page("127.0.0.1", server_->port());
    page.set_read_timeout(10, 0);
    const auto answer = page.Get("/?token=" + server_->token());
    ASSERT_TRUE(answer) << "the page did not answer with the streams open";
    EXPECT_EQ(answer->status, 200);
    // The streams are still live: each gets its heartbeat.
    for (const int fd : streams) {
        EXPECT_NE(read_until(fd, "heartbeat", std::chrono::seconds(10)).find("heartbeat"),
                  std::string::npos);
        close(fd);
    }
}

// Clients that trickle a request without the token, a byte every 200 ms (as slowloris
// does; each byte within the read timeout), are closed once the deadline for presenting
// the token has passed, while an authorized request answers meanwhile and an authorized
// event stream opened with them stays open past the deadline.
TEST_F(ViewLoadTest, SlowClientsWithoutTheTokenAreClosedAfterTheDeadline) {
    ServerOptions options;
    options.auth_deadline = std::chrono::milliseconds(1000);
    start(options);
    const int stream = open_stream();
    ASSERT_GE(stream, 0);
    constexpr int kSlow = 20;
    const std::string slow_request =
        "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Padding: " + std::string(1000, 'a');
    // (A connect can take a second or more: past httplib's listen backlog of 5, the kernel
    // drops the SYN and the client sends it again later; so each client has its own clock.)
    std::vector<int> slow(kSlow);
    std::vector<Clock::time_point> opened(kSlow);
    for (int i = 0; i < kSlow; ++i) {
        slow[i] = connect_to(server_->port());
        ASSERT_GE(slow[i], 0);
        opened[i] = Clock::now();
    }
    std::vector<double> closed_after(kSlow, -1.0);
    std::thread trickle([&] {
        // At most 30 s (before, they were never closed).
        const auto give_up = Clock::now() + std::chrono::seconds(30);
        for (std::size_t sent = 0; sent < slow_request.size() && Clock::now() < give_up;
             ++sent) {
            int open = 0;
            for (int i = 0; i < kSlow; ++i) {
                if (closed_after[i] >= 0) continue;
                if (closed_by_server(slow[i]) ||
                    !send_text(slow[i], slow_request.substr(sent, 1)))
                    closed_after[i] =
                        std::chrono::duration<double>(Clock::now() - opened[i]).count();
                else
                    ++open;
            }
            if (open == 0) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(status_code(), 200) << "the API did not answer with slow clients connected";
    trickle.join();  // every slow client closed, or 30 s passed
    for (int i = 0; i < kSlow; ++i) {
        EXPECT_GE(closed_after[i], 0.0) << "slow client " << i << " was never closed";
        // Not before the deadline (which starts when the server accepts the connection,
        // after the client's connect returns; 0.1 s of slack for the clocks' reading).
        EXPECT_GE(closed_after[i], 0.9) << "slow client " << i << " closed before the deadline";
        close(slow[i]);
    }
    // The authorized stream outlived the deadline.
    EXPECT_NE(read_until(stream, "heartbeat", std::chrono::seconds(10)).find("heartbeat"),
              std::string::npos);
    close(stream);
}

// Past the cap on connections a client is told so: a 503 whose text names the limit, then
// the connection closes; once a connection closes the server answers again.
TEST_F(ViewLoadTest, PastTheConnectionCapTheAnswerIs503SayingSo) {
    ServerOptions options;
    options.max_connections = 4;
    start(options);
    std::vector<int> streams;
    for (int i = 0; i < 4; ++i) {
        const int fd = open_stream();
        ASSERT_GE(fd, 0) << "stream " << i;
        streams.push_back(fd);
    }
    const int extra = connect_to(server_->port());
    ASSERT_GE(extra, 0);
    ASSERT_TRUE(send_text(extra, request("/api/status")));
    // Reads to the end: the server closes the connection after the refusal.
    const std::string refusal = read_until(extra, "\x01", std::chrono::seconds(10));
    close(extra);
    EXPECT_EQ(refusal.rfind("HTTP/1.1 503", 0), 0u) << refusal;
    EXPECT_NE(refusal.find("too many connections"), std::string::npos) << refusal;
    EXPECT_NE(refusal.find("at most 4 at once"), std::string::npos) << refusal;
    EXPECT_NE(refusal.find("Connection: close"), std::string::npos) << refusal;

    // A stream that closes frees its place (noticed at its next heartbeat).
    close(streams.back());
    streams.pop_back();
    int code = -1;
    const auto until = Clock::now() + std::chrono::seconds(10);
    while (code != 200 && Clock::now() < until) {
        code = status_code();
        if (code != 200) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_EQ(code, 200);
    for (const int fd : streams) close(fd);
}

}  // namespace
