#include "render/batch/claim_owner.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <climits>
#include <fstream>
#include <optional>
#include <sstream>
#include <string_view>

namespace octray::batch {
namespace {

std::string host_name() {
    char name[HOST_NAME_MAX + 1] = {};
    if (::gethostname(name, sizeof name - 1) != 0) return "unknown-host";
    return name;
}

// The start time of process `pid` (clock ticks after boot), or nullopt if it cannot be
// read. Field 2 of /proc/PID/stat, the command name, may hold spaces and parentheses:
// the fields after it are counted from its last ')'.
std::optional<unsigned long long> start_time(long pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(in, line)) return std::nullopt;
    const std::size_t close = line.rfind(')');
    if (close == std::string::npos) return std::nullopt;
    std::istringstream fields(line.substr(close + 1));
    std::string field;
    for (int k = 3; k <= 22; ++k)
        if (!(fields >> field)) return std::nullopt;
    unsigned long long ticks = 0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), ticks);
    if (error != std::errc() || end != field.data() + field.size()) return std::nullopt;
    return ticks;
}

}  // namespace

std::string current_owner() {
    const long pid = static_cast<long>(::getpid());
    const auto start = start_time(pid);
    return host_name() + ":" + std::to_string(pid) + ":" +
           (start ? std::to_string(*start) : std::string("?"));
}

bool owner_is_gone(const std::string& owner) {
    // HOST:PID:START, split at the last two colons.
    const std::size_t second = owner.rfind(':');
    if (second == std::string::npos || second == 0) return true;
    const std::size_t first = owner.rfind(':', second - 1);
    if (first == std::string::npos) return true;
    const std::string_view host = std::string_view(owner).substr(0, first);
    const std::string_view pid_text =
        std::string_view(owner).substr(first + 1, second - first - 1);
    const std::string_view start_text = std::string_view(owner).substr(second + 1);
    long pid = 0;
    const auto [end, error] =
        std::from_chars(pid_text.data(), pid_text.data() + pid_text.size(), pid);
    if (error != std::errc() || end != pid_text.data() + pid_text.size() || pid <= 0)
        return true;
    if (host != host_name()) return false;  // cannot be checked from here
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return true;
    // The PID runs (or is not ours to signal): gone only if it is another process.
    unsigned long long start = 0;
    const auto [start_end, start_error] =
        std::from_chars(start_text.data(), start_text.data() + start_text.size(), start);
    if (start_error != std::errc() || start_end != start_text.data() + start_text.size())
        return false;
    const auto now = start_time(pid);
    return now && *now != start;
}

}  // namespace octray::batch
