#include "rhi/pipeline_cache.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/atomic_file.h"
#include "core/log.h"
#include "rhi/device.h"

namespace shadel {
namespace {

constexpr char kMagic[8] = {'S', 'H', 'D', 'L', 'P', 'I', 'P', 'E'};
constexpr uint32_t kFormatVersion = 1;
constexpr uint32_t kEndianTag = 0x01020304;

struct FileHeader {
    char magic[8];
    uint32_t version;
    uint32_t endianTag;
    uint64_t payloadBytes;
    uint64_t payloadChecksum;
};
static_assert(sizeof(FileHeader) == 32);

// FNV-1a, 64 bits: enough to tell a damaged file from an intact one (not an adversary).
uint64_t checksum(const void* data, size_t size) {
    const uint8_t* bytes = static_cast<const uint8_t*>(data);
    uint64_t h = 0xCBF29CE484222325ull;
    for (size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 0x100000001B3ull;
    return h;
}

// The file's bytes, or a reason: only a regular file (O_NOFOLLOW: a symlink fails; O_NONBLOCK:
// opening a FIFO does not wait for a writer) of at most kMaxPipelineCacheBytes is read.
std::string readCacheFile(const std::string& path, std::string& bytes, bool& missing) {
    missing = false;
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    if (fd < 0) {
        if (errno == ENOENT) missing = true;
        if (errno == ELOOP) return "a symbolic link, not a regular file";
        return std::string("cannot open: ") + std::strerror(errno);
    }
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) return std::string("cannot stat: ") + std::strerror(errno);
    if (!S_ISREG(st.st_mode)) return "not a regular file";
    if (uint64_t(st.st_size) > kMaxPipelineCacheBytes)
        return format("%llu bytes, over the %llu MiB limit", (unsigned long long)st.st_size,
                      (unsigned long long)(kMaxPipelineCacheBytes >> 20));
    bytes.resize(size_t(st.st_size));
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::pread(fd, bytes.data() + done, bytes.size() - done, off_t(done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return std::string("cannot read: ") + std::strerror(errno);
        if (n == 0) return "shrank while being read";
        done += size_t(n);
    }
    return "";
}

std::string hex(const uint8_t* bytes, size_t n) {
    std::string s;
    for (size_t i = 0; i < n; ++i) s += format("%02x", bytes[i]);
    return s;
}

void createCache(const Device& device, PipelineCacheState& s, const void* data, size_t size) {
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = size;
    ci.pInitialData = data;
    VK_CHECK(vkCreatePipelineCache(device.device, &ci, nullptr, &s.cache));
    setName(device, s.cache, VK_OBJECT_TYPE_PIPELINE_CACHE, "pipelineCache");
}

void writeHeader(char* at, uint64_t payloadBytes, uint64_t payloadChecksum) {
    FileHeader h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kFormatVersion;
    h.endianTag = kEndianTag;
    h.payloadBytes = payloadBytes;
    h.payloadChecksum = payloadChecksum;
    std::memcpy(at, &h, sizeof h);
}

} // namespace

std::string pipelineCacheFileBytes(const void* data, size_t size) {
    std::string file(sizeof(FileHeader), '\0');
    file.append(static_cast<const char*>(data), size);
    writeHeader(file.data(), size, checksum(data, size));
    return file;
}

std::string pipelineCacheFile(const std::string& folder, const VkPhysicalDeviceProperties& props) {
    return folder + format("/pipelines-%04x-%04x.bin", props.vendorID, props.deviceID);
}

std::string checkPipelineCacheFile(const std::string& bytes,
                                   const VkPhysicalDeviceProperties& props, const char** payload,
                                   size_t* payloadBytes) {
    FileHeader h{};
    if (bytes.size() < sizeof h) return format("truncated header (%zu bytes)", bytes.size());
    std::memcpy(&h, bytes.data(), sizeof h);
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return "bad magic";
    if (h.version != kFormatVersion || h.endianTag != kEndianTag)
        return format("format version %u (want %u)", h.version, kFormatVersion);
    const size_t data = bytes.size() - sizeof h;
    if (h.payloadBytes != data)
        return format("%zu bytes of cache data, the header says %llu", data,
                      (unsigned long long)h.payloadBytes);
    const char* p = bytes.data() + sizeof h;
    if (checksum(p, data) != h.payloadChecksum) return "checksum mismatch";
    VkPipelineCacheHeaderVersionOne v{};
    if (data < sizeof v) return format("driver header truncated (%zu bytes)", data);
    std::memcpy(&v, p, sizeof v);
    if (v.headerSize < sizeof v || v.headerSize > data)
        return format("driver header size %u", v.headerSize);
    if (v.headerVersion != VK_PIPELINE_CACHE_HEADER_VERSION_ONE)
        return format("driver header version %d", int(v.headerVersion));
    if (v.vendorID != props.vendorID || v.deviceID != props.deviceID)
        return format("made for device %04x:%04x, this is %04x:%04x", v.vendorID, v.deviceID,
                      props.vendorID, props.deviceID);
    if (std::memcmp(v.pipelineCacheUUID, props.pipelineCacheUUID, VK_UUID_SIZE) != 0)
        return format("driver cache UUID %s, this driver's is %s",
                      hex(v.pipelineCacheUUID, VK_UUID_SIZE).c_str(),
                      hex(props.pipelineCacheUUID, VK_UUID_SIZE).c_str());
    *payload = p;
    *payloadBytes = data;
    return "";
}

void createPipelineCache(const Device& device, PipelineCacheState& s, const std::string& folder) {
    s = {};
    if (folder.empty()) {
        s.status = "off";
        createCache(device, s, nullptr, 0);
        return;
    }
    s.path = pipelineCacheFile(folder, device.properties);
    std::string bytes;
    bool missing = false;
    std::string why = readCacheFile(s.path, bytes, missing);
    const char* payload = nullptr;
    size_t payloadBytes = 0;
    if (why.empty())
        why = checkPipelineCacheFile(bytes, device.properties, &payload, &payloadBytes);
    if (missing) {
        s.status = "created";
    } else if (!why.empty()) {
        s.status = "rejected";
        s.reason = why;
        SHADEL_WARN("pipeline cache %s: %s; rebuilding", s.path.c_str(), why.c_str());
    } else {
        s.status = "loaded";
        s.loadedBytes = payloadBytes;
        s.lastBytes = payloadBytes;
        s.lastChecksum = checksum(payload, payloadBytes);
        SHADEL_DEBUG("pipeline cache %s: loaded %zu bytes", s.path.c_str(), payloadBytes);
    }
    createCache(device, s, payload, payload ? payloadBytes : 0);
}

bool savePipelineCache(const Device& device, PipelineCacheState& s, bool compiledAny) {
    if (!s.cache || s.path.empty()) return true;
    // A device that compiled nothing (shadel info, bake) leaves a good file as it is.
    if (!compiledAny && s.status != "rejected") return true;
    size_t size = 0;
    VK_CHECK(vkGetPipelineCacheData(device.device, s.cache, &size, nullptr));
    std::string file(sizeof(FileHeader) + size, '\0');
    if (size)
        VK_CHECK(vkGetPipelineCacheData(device.device, s.cache, &size,
                                        file.data() + sizeof(FileHeader)));
    file.resize(sizeof(FileHeader) + size);
    if (size < sizeof(VkPipelineCacheHeaderVersionOne)) return true; // nothing a driver could use
    if (size > kMaxPipelineCacheBytes) { // the next run would refuse it: keep the file there is
        if (s.saveError.empty())
            SHADEL_WARN("pipeline cache not saved: %s: %zu bytes, over the %llu MiB limit",
                        s.path.c_str(), size, (unsigned long long)(kMaxPipelineCacheBytes >> 20));
        s.saveError = "over the size limit";
        return false;
    }
    const uint64_t sum = checksum(file.data() + sizeof(FileHeader), size);
    if (sum == s.lastChecksum && size == s.lastBytes) return true; // (a rejected file: 0, 0)
    writeHeader(file.data(), size, sum);
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(s.path).parent_path(), ec);
    // A symlink, FIFO or device at the path is replaced, never written through.
    struct stat st {};
    if (::lstat(s.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
        ::unlink(s.path.c_str());
    std::string error = writeFileAtomically(s.path, file.data(), file.size());
    if (!error.empty()) {
        if (s.saveError.empty()) SHADEL_WARN("pipeline cache not saved: %s", error.c_str());
        s.saveError = error;
        return false;
    }
    s.savedBytes = size;
    s.lastBytes = size;
    s.lastChecksum = sum;
    SHADEL_DEBUG("pipeline cache %s: saved %zu bytes", s.path.c_str(), size);
    return true;
}

void destroyPipelineCache(const Device& device, PipelineCacheState& s, bool compiledAny) {
    if (!s.cache) return;
    savePipelineCache(device, s, compiledAny);
    vkDestroyPipelineCache(device.device, s.cache, nullptr);
    s.cache = VK_NULL_HANDLE;
}

} // namespace shadel
