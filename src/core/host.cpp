#include "core/host.h"

#include <fstream>
#include <sstream>
#include <thread>

namespace shadel {

static std::string_view trim(std::string_view s) {
    const char* space = " \t\r";
    size_t first = s.find_first_not_of(space);
    if (first == std::string_view::npos) return {};
    return s.substr(first, s.find_last_not_of(space) - first + 1);
}

std::string cpuModelFromCpuinfo(std::string_view cpuinfo) {
    const std::string_view keys[] = {"model name", "Processor", "cpu model"};
    for (std::string_view key : keys) {
        size_t start = 0;
        while (start < cpuinfo.size()) {
            size_t end = cpuinfo.find('\n', start);
            if (end == std::string_view::npos) end = cpuinfo.size();
            std::string_view line = cpuinfo.substr(start, end - start);
            start = end + 1;
            size_t colon = line.find(':');
            if (colon == std::string_view::npos || trim(line.substr(0, colon)) != key) continue;
            std::string_view value = trim(line.substr(colon + 1));
            if (!value.empty()) return std::string(value);
        }
    }
    return "unknown";
}

HostInfo hostInfo() {
    HostInfo h;
    h.threads = std::thread::hardware_concurrency();
    std::ifstream in("/proc/cpuinfo");
    std::ostringstream text;
    if (in) text << in.rdbuf();
    h.cpu = cpuModelFromCpuinfo(text.str());
    return h;
}

} // namespace shadel
