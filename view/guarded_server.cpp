#include "view/guarded_server.h"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <functional>
#include <list>
#include <map>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace octray::view {
namespace {

using Clock = std::chrono::steady_clock;

// What the thread running process_and_close_socket is to do with its connection: serve it,
// refuse it with a 503 (on a thread of its own, which lingers up to a second so that the
// client reads the answer before the close), or, past even the refusers' cap (a flood),
// drop it at once on the listener's thread after one non-blocking write of the 503.
enum class Mode { serve, refuse, drop };
thread_local Mode t_mode = Mode::serve;

// Refusals in flight at once; past this, connections are dropped.
constexpr int kMaxRefusing = 32;
constexpr auto kRefusalLinger = std::chrono::milliseconds(1000);

// Waits up to `ms` for `events` on `fd`; true if any (or an error or hang-up) came.
bool wait_for(int fd, short events, long ms) {
    const auto until = Clock::now() + std::chrono::milliseconds(ms);
    for (;;) {
        pollfd p{fd, events, 0};
        const long left = std::max<long>(
            0, std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now())
                   .count());
        const int n = ::poll(&p, 1, static_cast<int>(std::min<long>(left, 1 << 30)));
        if (n > 0) return true;
        if (n == 0) return false;
        if (errno != EINTR) return false;
    }
}

ssize_t recv_some(int fd, char* data, std::size_t size, int flags) {
    for (;;) {
        const ssize_t n = ::recv(fd, data, size, flags);
        if (n >= 0 || errno != EINTR) return n;
    }
}

ssize_t send_some(int fd, const char* data, std::size_t size, int flags) {
    for (;;) {
        const ssize_t n = ::send(fd, data, size, flags | MSG_NOSIGNAL);
        if (n >= 0 || errno != EINTR) return n;
    }
}

void address_of(int fd, bool peer, std::string& ip, int& port) {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    auto* a = reinterpret_cast<sockaddr*>(&address);
    if ((peer ? ::getpeername(fd, a, &length) : ::getsockname(fd, a, &length)) != 0) return;
    char host[NI_MAXHOST];
    char service[NI_MAXSERV];
    if (::getnameinfo(a, length, host, sizeof(host), service, sizeof(service),
                      NI_NUMERICHOST | NI_NUMERICSERV) != 0)
        return;
    ip = host;
    port = std::atoi(service);
}

// httplib::Stream over a connected socket, as httplib's own SocketStream (which Debian's
// header does not declare): reads buffered, each read and write waiting at most its
// timeout, and a write refused once the peer has closed.
class ConnectionStream final : public httplib::Stream {
  public:
    ConnectionStream(int fd, long read_ms, long write_ms)
        : fd_(fd), read_ms_(read_ms), write_ms_(write_ms) {}

    bool buffered() const { return pos_ < len_; }

    bool is_readable() const override { return buffered() || wait_for(fd_, POLLIN, read_ms_); }

    bool is_writable() const override {
        if (!wait_for(fd_, POLLOUT, write_ms_)) return false;
        // Still open? Readable with nothing to read means the peer closed.
        if (!wait_for(fd_, POLLIN, 0)) return true;
        char byte;
        const ssize_t n = recv_some(fd_, &byte, 1, MSG_PEEK | MSG_DONTWAIT);
        return n > 0 || (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK));
    }

    ssize_t read(char* ptr, std::size_t size) override {
        if (!buffered()) {
            if (!wait_for(fd_, POLLIN, read_ms_)) return -1;
            if (size >= sizeof(buffer_)) return recv_some(fd_, ptr, size, 0);
            const ssize_t n = recv_some(fd_, buffer_, sizeof(buffer_), 0);
            if (n <= 0) return n;
            pos_ = 0;
            len_ = static_cast<std::size_t>(n);
        }
        const std::size_t n = std::min(size, len_ - pos_);
        std::memcpy(ptr, buffer_ + pos_, n);
        pos_ += n;
        return static_cast<ssize_t>(n);
    }

    ssize_t write(const char* ptr, std::size_t size) override {
        if (!is_writable()) return -1;
        return send_some(fd_, ptr, size, 0);
    }

    void get_remote_ip_and_port(std::string& ip, int& port) const override {
        address_of(fd_, true, ip, port);
    }
    void get_local_ip_and_port(std::string& ip, int& port) const override {
        address_of(fd_, false, ip, port);
    }
    socket_t socket() const override { return fd_; }

  private:
    int fd_;
    long read_ms_;
    long write_ms_;
    char buffer_[4096];
    std::size_t pos_ = 0;
    std::size_t len_ = 0;
};

struct Connection {
    int fd;
    Clock::time_point deadline;
    std::atomic<bool> authenticated{false};
    bool shut = false;  // by the watchdog (under State::mutex)
};

thread_local Connection* t_connection = nullptr;

}  // namespace

struct GuardedServer::State {
    ConnectionLimits limits;
    std::string refusal;  // the raw 503 answer past the cap

    std::mutex mutex;
    std::condition_variable changed;
    std::list<Connection*> connections;  // open and served now
    int serving = 0;                     // connection threads running (Mode::serve)
    int refusing = 0;                    // refusal threads running
    bool quit = false;                   // the watchdog ends
    std::thread watchdog;

    explicit State(ConnectionLimits l) : limits(l) {
        const std::string text =
            "503 Service Unavailable: too many connections: this viewer serves at most " +
            std::to_string(limits.max_connections) +
            " at once (close a tab or an idle client, then retry)\n";
        refusal =
            "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain\r\n"
            "Cache-Control: no-store\r\nRetry-After: 1\r\nConnection: close\r\n"
            "Content-Length: " +
            std::to_string(text.size()) + "\r\n\r\n" + text;
    }

    // Shuts down the connections that did not authenticate in time, until `quit`.
    void watch() {
        std::unique_lock lock(mutex);
        while (!quit) {
            changed.wait_for(lock, std::chrono::milliseconds(50));
            const auto now = Clock::now();
            for (Connection* c : connections) {
                if (!c->shut && !c->authenticated && now >= c->deadline) {
                    ::shutdown(c->fd, SHUT_RDWR);
                    c->shut = true;
                }
            }
        }
    }

    void refuse(int fd, Mode mode) {
        if (mode == Mode::drop) {
            send_some(fd, refusal.data(), refusal.size(), MSG_DONTWAIT);
        } else if (wait_for(fd, POLLOUT, kRefusalLinger.count())) {
            send_some(fd, refusal.data(), refusal.size(), 0);
            // Let the client read the answer: closing with its request unread would reset
            // the connection, which may discard the answer before the client reads it.
            ::shutdown(fd, SHUT_WR);
            const auto until = Clock::now() + kRefusalLinger;
            char sink[1024];
            while (Clock::now() < until && wait_for(fd, POLLIN, 100)) {
                if (recv_some(fd, sink, sizeof(sink), MSG_DONTWAIT) == 0) break;
            }
        }
        ::close(fd);
    }
};

namespace {

// httplib's task queue, one thread per connection: a connection is served on a thread of
// its own while fewer than max_connections are; past that, it is refused (a 503).
class ConnectionQueue final : public httplib::TaskQueue {
  public:
    explicit ConnectionQueue(std::shared_ptr<GuardedServer::State> state)
        : state_(std::move(state)) {}
    ~ConnectionQueue() override { shutdown(); }

    void enqueue(std::function<void()> fn) override {
        GuardedServer::State& s = *state_;
        std::unique_lock lock(s.mutex);
        reap();
        Mode mode = Mode::drop;
        if (s.serving < s.limits.max_connections)
            mode = Mode::serve;
        else if (s.refusing < kMaxRefusing)
            mode = Mode::refuse;
        if (mode != Mode::drop) {
            int* count = mode == Mode::serve ? &s.serving : &s.refusing;
            const std::uint64_t id = next_id_++;
            try {
                threads_.emplace(id, std::thread([this, fn, mode, id, count] {
                                     t_mode = mode;
                                     fn();
                                     const std::lock_guard done(state_->mutex);
                                     --*count;
                                     finished_.push_back(id);
                                 }));
                ++*count;
                return;
            } catch (const std::system_error&) {
                mode = Mode::drop;  // no thread to be had: refuse on this one
            }
        }
        lock.unlock();
        t_mode = Mode::drop;
        fn();
        t_mode = Mode::serve;
    }

    void shutdown() override {
        std::map<std::uint64_t, std::thread> threads;
        {
            const std::lock_guard lock(state_->mutex);
            threads.swap(threads_);
            finished_.clear();
        }
        for (auto& [id, thread] : threads) thread.join();
    }

  private:
    // Joins the threads that have finished (under the state's mutex).
    void reap() {
        for (const std::uint64_t id : finished_) {
            const auto it = threads_.find(id);
            if (it == threads_.end()) continue;
            it->second.join();
            threads_.erase(it);
        }
        finished_.clear();
    }

    std::shared_ptr<GuardedServer::State> state_;
    std::map<std::uint64_t, std::thread> threads_;
    std::vector<std::uint64_t> finished_;
    std::uint64_t next_id_ = 0;
};

}  // namespace

GuardedServer::GuardedServer(ConnectionLimits limits)
    : state_(std::make_shared<State>(limits)) {
    new_task_queue = [state = state_] { return new ConnectionQueue(state); };
    state_->watchdog = std::thread([state = state_] { state->watch(); });
}

GuardedServer::~GuardedServer() {
    {
        const std::lock_guard lock(state_->mutex);
        state_->quit = true;
    }
    state_->changed.notify_all();
    state_->watchdog.join();
}

void GuardedServer::mark_authenticated() {
    if (t_connection != nullptr) t_connection->authenticated = true;
}

void GuardedServer::end_connections() {
    const std::lock_guard lock(state_->mutex);
    for (Connection* c : state_->connections) ::shutdown(c->fd, SHUT_RD);
}

const ConnectionLimits& GuardedServer::limits() const { return state_->limits; }

bool GuardedServer::process_and_close_socket(socket_t sock) {
    if (t_mode != Mode::serve) {
        state_->refuse(sock, t_mode);
        return false;
    }
    Connection connection{sock, Clock::now() + state_->limits.auth_deadline};
    {
        const std::lock_guard lock(state_->mutex);
        state_->connections.push_back(&connection);
    }
    t_connection = &connection;
    const auto ms = [](time_t sec, time_t usec) {
        return long(sec) * 1000 + long(usec) / 1000;
    };
    ConnectionStream stream(sock, ms(read_timeout_sec_, read_timeout_usec_),
                            ms(write_timeout_sec_, write_timeout_usec_));
    // httplib's keep-alive loop: up to keep_alive_max_count_ requests, each waited for at
    // most the keep-alive timeout (in slices, so that a stopped server is noticed).
    const auto next_request = [&] {
        if (stream.buffered()) return true;
        const auto until = Clock::now() + std::chrono::seconds(keep_alive_timeout_sec_);
        while (svr_sock_ != INVALID_SOCKET) {
            if (wait_for(sock, POLLIN, 100)) return true;
            if (Clock::now() >= until) return false;
        }
        return false;
    };
    bool ok = false;
    for (std::size_t left = keep_alive_max_count_;
         left > 0 && svr_sock_ != INVALID_SOCKET && next_request(); --left) {
        bool connection_closed = false;
        ok = process_request(stream, left == 1, connection_closed, nullptr);
        if (!ok || connection_closed) break;
    }
    t_connection = nullptr;
    {
        // Off the watchdog's list before the descriptor is closed (and its number reused).
        const std::lock_guard lock(state_->mutex);
        state_->connections.remove(&connection);
    }
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
    return ok;
}

}  // namespace octray::view
