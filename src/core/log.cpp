#include "core/log.h"

#include <cstdarg>
#include <mutex>

namespace shadel {

static LogLevel g_level = LogLevel::Info;
static thread_local LogLevel t_floor = LogLevel::Debug; // ScopedThreadLogLevel
static std::mutex g_logMutex;

ScopedThreadLogLevel::ScopedThreadLogLevel(LogLevel atLeast) : m_previous(t_floor) {
    t_floor = atLeast;
}
ScopedThreadLogLevel::~ScopedThreadLogLevel() {
    t_floor = m_previous;
}

void setLogLevel(LogLevel level) {
    g_level = level;
}
LogLevel logLevel() {
    return g_level;
}

void logLine(LogLevel level, const char* fmt, ...) {
    if (level < g_level || level < t_floor) return;
    static const char* prefix[] = {"debug: ", "", "warning: ", "error: "};
    std::lock_guard lock(g_logMutex);
    std::fputs(prefix[int(level)], stderr);
    va_list args;
    va_start(args, fmt);
    std::vfprintf(stderr, fmt, args);
    va_end(args);
    std::fputc('\n', stderr);
}

std::string format(const char* fmt, ...) {
    va_list args;
    va_start(args, fmt);
    va_list copy;
    va_copy(copy, args);
    int n = std::vsnprintf(nullptr, 0, fmt, copy);
    va_end(copy);
    std::string out(n > 0 ? size_t(n) : 0, '\0');
    if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
    va_end(args);
    return out;
}

} // namespace shadel
