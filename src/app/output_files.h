#pragma once
// The files a command writes (images, stats, bench JSON): checked before any work starts, and
// written whole or not at all (core/atomic_file.h). Failures throw InputError with one line
// naming the file and the reason.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace shadel {

// Throws unless `path` (the value of `flag`) can be created: fails fast, before minutes of
// rendering, on a missing or read-only folder or a path that is a directory.
void requireCreatableOutput(const char* flag, const std::string& path);

// Throws unless the given outputs (flag, path; empty paths skipped) name different files: the
// same file given twice (also through a link or "./") would be overwritten by the later write.
void requireDistinctOutputs(const std::vector<std::pair<const char*, std::string>>& outputs);

// Writes the whole file atomically; throws InputError "<path>: <strerror>" on any failure.
void writeOutputFile(const std::string& path, const void* data, size_t size);
void writeOutputFile(const std::string& path, const std::string& text);

// RGBA8 pixels encoded as an RGB PNG in memory.
std::vector<uint8_t> encodePngRgb(const std::vector<uint8_t>& rgba, uint32_t width,
                                  uint32_t height);
// The same with the alpha channel kept (an RGBA PNG).
std::vector<uint8_t> encodePngRgba(const std::vector<uint8_t>& rgba, uint32_t width,
                                   uint32_t height);

} // namespace shadel
