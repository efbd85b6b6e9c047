#pragma once
// Minimal logging: one line per message on stderr, printf-style.
#include <cstdio>
#include <string>

namespace shadel {

enum class LogLevel { Debug, Info, Warn, Error };

void setLogLevel(LogLevel level);
LogLevel logLevel();

// Raises the level for the calling thread only, while it lives: a worker repeating work whose
// warnings the main thread already gave (the next frame's scene import) stays quiet without
// silencing the other threads.
class ScopedThreadLogLevel {
public:
    explicit ScopedThreadLogLevel(LogLevel atLeast);
    ~ScopedThreadLogLevel();
    ScopedThreadLogLevel(const ScopedThreadLogLevel&) = delete;
    ScopedThreadLogLevel& operator=(const ScopedThreadLogLevel&) = delete;

private:
    LogLevel m_previous;
};
void logLine(LogLevel level, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

} // namespace shadel

#define SHADEL_DEBUG(...) ::shadel::logLine(::shadel::LogLevel::Debug, __VA_ARGS__)
#define SHADEL_INFO(...) ::shadel::logLine(::shadel::LogLevel::Info, __VA_ARGS__)
#define SHADEL_WARN(...) ::shadel::logLine(::shadel::LogLevel::Warn, __VA_ARGS__)
#define SHADEL_ERROR(...) ::shadel::logLine(::shadel::LogLevel::Error, __VA_ARGS__)
