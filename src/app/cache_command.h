#pragma once
// `shadel cache [clean]`: where the bake cache is, how big, and removing it.
#include <cstdint>
#include <string>

namespace shadel {

// Prints the cache folder, its size and limit; with clean, removes every cache file (and
// temporary files of interrupted writers) first. Returns the exit code.
int runCacheCommand(const std::string& dir, bool clean, uint64_t limitBytes);

} // namespace shadel
