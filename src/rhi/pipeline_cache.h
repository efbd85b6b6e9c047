#pragma once
// The device's pipeline cache, kept on disk between runs: a warm run finds the driver's compiled
// pipelines instead of compiling them again (tens of seconds of shader compilation on a CPU
// device).
//
// File (one per physical device, in the cache folder): a header { magic "SHDLPIPE", format
// version, endianness tag, payload size, payload checksum } then the driver's cache data, which
// starts with VkPipelineCacheHeaderVersionOne. The file is read only when it is a regular file
// (not followed through a symlink, never a FIFO or device) of at most kMaxPipelineCacheBytes;
// its checksum and the driver header (size, version, vendor, device, pipeline cache UUID) must
// match this device. Anything else is reported on one line ("pipeline cache FILE: REASON;
// rebuilding"), never given to the driver, and replaced at the next save. Saves are atomic; a
// failed save is a warning (the render itself succeeded).
#include <cstdint>
#include <string>

#include "rhi/vk.h"

namespace shadel {

struct Device;
struct Gpu;

constexpr uint64_t kMaxPipelineCacheBytes = uint64_t(256) << 20;

struct PipelineCacheState {
    VkPipelineCache cache = VK_NULL_HANDLE;
    std::string path;         // "" = not kept on disk (off, or no folder given)
    std::string status;       // off (in memory only) | created (no file yet) | loaded | rejected
    std::string reason;       // why the file was rejected (then it is replaced at the next save)
    std::string saveError;    // the last failed save's reason ("" = none failed)
    uint64_t loadedBytes = 0; // driver data given to vkCreatePipelineCache
    uint64_t savedBytes = 0;  // driver data written by this process (0: nothing new to write)
    uint64_t lastChecksum = 0, lastBytes = 0; // of the data on disk (loaded or last saved)
};

// The device's cache (kept by its pipeline library, rhi/pipeline.cpp). createGpu makes it in
// memory; keepPipelineCacheIn(gpu, folder), before any pipeline is built, replaces it with one
// loaded from the folder's file when that checks out (else an empty one), saved there when the
// device goes (destroyGpu) and by savePipelineCache.
void keepPipelineCacheIn(Gpu& gpu, const std::string& folder);
// Writes the cache's data to its file if it changed since it was loaded or last saved and this
// device compiled something. Returns false (and warns once) if the write failed.
bool savePipelineCache(Gpu& gpu);
PipelineCacheState pipelineCacheState(const Gpu& gpu);

// The file name for this device inside `folder`.
std::string pipelineCacheFile(const std::string& folder, const VkPhysicalDeviceProperties& props);
// The file's bytes for the driver's cache data `data` (header, then the data).
std::string pipelineCacheFileBytes(const void* data, size_t size);
// Checks a cache file's bytes against the device. Returns "" if usable, else the reason; on
// success *payload/*payloadBytes point at the driver data inside `bytes`.
std::string checkPipelineCacheFile(const std::string& bytes,
                                   const VkPhysicalDeviceProperties& props, const char** payload,
                                   size_t* payloadBytes);

// The pieces the library uses: create (folder "" = in memory only), save, destroy (saving first).
void createPipelineCache(const Device& device, PipelineCacheState& s, const std::string& folder);
bool savePipelineCache(const Device& device, PipelineCacheState& s, bool compiledAny);
void destroyPipelineCache(const Device& device, PipelineCacheState& s, bool compiledAny);

} // namespace shadel
