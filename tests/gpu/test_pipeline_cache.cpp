// The device's pipeline cache on disk (rhi/pipeline_cache.h): a run writes it, the next run's
// fresh device loads it, and a bad file (wrong driver header, truncated, random bytes, a
// symlink, a FIFO) is reported, never given to the driver, and replaced by a good one.
#include "gpu_test_env.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rhi/pipeline.h"
#include "rhi/pipeline_cache.h"

using namespace shadel;
using namespace shadel::test;

namespace {

std::string readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void writeBytes(const std::string& path, const std::string& bytes) {
    std::filesystem::remove(path);
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// A folder of its own (removed with everything in it).
struct TempFolder {
    std::string path;
    explicit TempFolder(const std::string& name) : path(tempPath(name)) {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempFolder() { std::filesystem::remove_all(path); }
};

// A fresh device keeping its pipeline cache in `folder`, with the validation layer; it builds
// one compute pipeline and one graphics pipeline (which must succeed whatever the file held)
// and saves the cache when it goes.
struct CacheDevice {
    Gpu gpu;
    explicit CacheDevice(const std::string& folder) {
        DeviceDesc d;
        d.validation = true;
        createGpu(gpu, d);
        keepPipelineCacheIn(gpu, folder);
    }
    ~CacheDevice() { destroyGpu(gpu); }
    PipelineCacheState cache() const { return pipelineCacheState(gpu); }
    void buildPipelines() {
        Pipeline compute = createComputePipeline(gpu, "test.cacheProbe", "tests_probe.comp.spv");
        EXPECT_NE(compute.pipeline, VK_NULL_HANDLE);
        GraphicsPipelineDesc g;
        g.name = "test.cacheDepth";
        g.vertexShader = "oit_fullscreen.vert.spv";
        g.depthFormat = VK_FORMAT_D32_SFLOAT;
        Pipeline graphics = createGraphicsPipeline(gpu, g);
        EXPECT_NE(graphics.pipeline, VK_NULL_HANDLE);
        destroy(gpu, compute);
        destroy(gpu, graphics);
        EXPECT_EQ(gpu.device.validationErrors.load(), 0u);
    }
};

// The driver data of a good file, rewrapped after `edit` (so only the driver header is wrong).
std::string withDriverHeader(const std::string& file,
                             void (*edit)(VkPipelineCacheHeaderVersionOne&)) {
    std::string data = file.substr(32); // after the 32-byte file header
    VkPipelineCacheHeaderVersionOne h{};
    std::memcpy(&h, data.data(), sizeof h);
    edit(h);
    std::memcpy(data.data(), &h, sizeof h);
    return pipelineCacheFileBytes(data.data(), data.size());
}

struct Output {
    int exitCode = -1;
    std::string stderrText;
};

// `shadel render` of a small forward frame with its cache folder, stats to `stats`.
Output renderWithCache(const std::string& folder, const std::string& stats,
                       const std::string& globalFlags = "") {
    std::string errFile = tempPath("pipeline-cache-stderr.txt");
    std::string cmd = "env SHADEL_CACHE_DIR=" + folder + " timeout 300 " + SHADEL_BINARY + " " +
                      globalFlags +
                      " render --scene builtin:default --mode forward --size 64x36 --stats " +
                      stats + " --out " + folder + "/frame.png >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    Output o;
    o.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.stderrText = readBytes(errFile);
    std::filesystem::remove(errFile);
    return o;
}

} // namespace

// A cold run writes the file; a warm run in a new process loads all of it; random bytes in its
// place are reported on one line and replaced, and the render still succeeds.
TEST(PipelineCache, ASecondRunLoadsWhatTheFirstSaved) {
    TempFolder folder("pipeline-cache-cli");
    std::string stats = folder.path + "/stats.json";
    Output cold = renderWithCache(folder.path, stats);
    ASSERT_EQ(cold.exitCode, 0) << cold.stderrText;
    nlohmann::json c = takeJsonFile(stats)["pipeline_cache"];
    EXPECT_EQ(c["status"], "created");
    EXPECT_EQ(c["loaded_bytes"].get<uint64_t>(), 0u);
    const uint64_t saved = c["saved_bytes"].get<uint64_t>();
    EXPECT_GT(saved, 0u);
    const std::string file = c["file"].get<std::string>();
    ASSERT_EQ(std::filesystem::path(file).parent_path(), std::filesystem::path(folder.path));
    EXPECT_EQ(std::filesystem::file_size(file), saved + 32); // header + the driver's data

    Output warm = renderWithCache(folder.path, stats);
    ASSERT_EQ(warm.exitCode, 0) << warm.stderrText;
    nlohmann::json w = takeJsonFile(stats)["pipeline_cache"];
    EXPECT_EQ(w["status"], "loaded");
    EXPECT_EQ(w["loaded_bytes"].get<uint64_t>(), saved);
    std::printf("[ figures ] pipeline cache: %llu bytes saved by the cold run, %llu loaded by the "
                "warm run (which saved %llu more)\n",
                (unsigned long long)saved, (unsigned long long)w["loaded_bytes"].get<uint64_t>(),
                (unsigned long long)w["saved_bytes"].get<uint64_t>());

    std::string noise(4096, '\0');
    std::mt19937 random(7);
    for (char& ch : noise) ch = char(random());
    writeBytes(file, noise);
    Output bad = renderWithCache(folder.path, stats);
    ASSERT_EQ(bad.exitCode, 0) << bad.stderrText;
    EXPECT_NE(bad.stderrText.find("pipeline cache " + file + ": bad magic; rebuilding"),
              std::string::npos)
        << bad.stderrText;
    nlohmann::json b = takeJsonFile(stats)["pipeline_cache"];
    EXPECT_EQ(b["status"], "rejected");
    EXPECT_EQ(b["reason"], "bad magic");
    EXPECT_EQ(b["loaded_bytes"].get<uint64_t>(), 0u);
    EXPECT_GT(b["saved_bytes"].get<uint64_t>(), 0u);
    EXPECT_EQ(readBytes(file).substr(0, 8), "SHDLPIPE"); // replaced by a good file
}

// --pipeline-cache off: no file is read or written (cold compiles); a value other than on or
// off is one error line and exit code 2.
TEST(PipelineCache, OffKeepsNoFileAndABadValueIsAnInputError) {
    TempFolder folder("pipeline-cache-off");
    std::string stats = folder.path + "/stats.json";
    Output off = renderWithCache(folder.path, stats, "--pipeline-cache off");
    ASSERT_EQ(off.exitCode, 0) << off.stderrText;
    nlohmann::json c = takeJsonFile(stats)["pipeline_cache"];
    EXPECT_EQ(c["status"], "off");
    EXPECT_EQ(c["file"], "");
    EXPECT_EQ(c["saved_bytes"].get<uint64_t>(), 0u);
    for (const auto& entry : std::filesystem::directory_iterator(folder.path))
        EXPECT_NE(entry.path().filename().string().rfind("pipelines-", 0), 0u) << entry.path();
    Output bad = renderWithCache(folder.path, stats, "--pipeline-cache maybe");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.stderrText.find("--pipeline-cache"), std::string::npos) << bad.stderrText;
    EXPECT_EQ(std::count(bad.stderrText.begin(), bad.stderrText.end(), '\n'), 1) << bad.stderrText;
}

// Every kind of bad file, on a fresh device each: rejected with its reason, the pipelines still
// build (without validation errors), and the file left behind is one the next device loads.
TEST(PipelineCache, ABadFileIsReportedAndReplaced) {
    TempFolder folder("pipeline-cache-bad");
    std::string good, path;
    {
        CacheDevice d(folder.path);
        EXPECT_EQ(d.cache().status, "created");
        path = d.cache().path;
        d.buildPipelines();
    }
    good = readBytes(path);
    ASSERT_GE(good.size(), 32u + sizeof(VkPipelineCacheHeaderVersionOne));
    {
        CacheDevice d(folder.path);
        EXPECT_EQ(d.cache().status, "loaded");
        EXPECT_EQ(d.cache().loadedBytes, good.size() - 32);
    }

    std::string noise(good.size(), '\0');
    std::mt19937 random(11);
    for (char& ch : noise) ch = char(random());
    struct Case {
        const char* what;
        std::string bytes; // written as a regular file, unless a symlink or a FIFO below
        const char* reason;
    };
    std::vector<Case> cases = {
        {"random bytes", noise, "bad magic"},
        {"truncated", good.substr(0, good.size() / 2), "the header says"},
        {"truncated header", good.substr(0, 20), "truncated header"},
        {"another driver's cache",
         withDriverHeader(
             good, [](VkPipelineCacheHeaderVersionOne& h) { h.pipelineCacheUUID[0] ^= 0xFF; }),
         "driver cache UUID"},
        {"another device's cache",
         withDriverHeader(good, [](VkPipelineCacheHeaderVersionOne& h) { h.deviceID += 1; }),
         "made for device"},
        {"a driver header of the wrong version",
         withDriverHeader(good,
                          [](VkPipelineCacheHeaderVersionOne& h) {
                              h.headerVersion = VkPipelineCacheHeaderVersion(2);
                          }),
         "driver header version"},
        {"a symlink to a good file", "", "symbolic link"},
        {"a FIFO", "", "not a regular file"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::filesystem::remove(path);
        if (std::string(c.what) == "a symlink to a good file") {
            writeBytes(path + ".target", good);
            std::filesystem::create_symlink(path + ".target", path);
        } else if (std::string(c.what) == "a FIFO") {
            ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
        } else {
            writeBytes(path, c.bytes);
        }
        {
            CacheDevice d(folder.path);
            EXPECT_EQ(d.cache().status, "rejected");
            EXPECT_NE(d.cache().reason.find(c.reason), std::string::npos) << d.cache().reason;
            EXPECT_EQ(d.cache().loadedBytes, 0u);
            d.buildPipelines();
        }
        EXPECT_TRUE(std::filesystem::is_regular_file(std::filesystem::symlink_status(path)));
        CacheDevice next(folder.path);
        EXPECT_EQ(next.cache().status, "loaded") << next.cache().reason;
        EXPECT_GT(next.cache().loadedBytes, 0u);
    }
    // The symlink's target was read by nobody and written by nobody.
    EXPECT_EQ(readBytes(path + ".target"), good);
}

// The header check on its own: a good file passes and says where the driver data is.
TEST(PipelineCache, TheHeaderCheckAcceptsAGoodFileOfThisDevice) {
    Gpu& gpu = sharedGpu();
    size_t size = 0;
    ASSERT_EQ(
        vkGetPipelineCacheData(gpu.device.device, pipelineCacheState(gpu).cache, &size, nullptr),
        VK_SUCCESS);
    std::string data(size, '\0');
    ASSERT_EQ(vkGetPipelineCacheData(gpu.device.device, pipelineCacheState(gpu).cache, &size,
                                     data.data()),
              VK_SUCCESS);
    data.resize(size);
    std::string file = pipelineCacheFileBytes(data.data(), data.size());
    const char* payload = nullptr;
    size_t payloadBytes = 0;
    EXPECT_EQ(checkPipelineCacheFile(file, gpu.device.properties, &payload, &payloadBytes), "");
    EXPECT_EQ(payloadBytes, data.size());
    EXPECT_EQ(std::string(payload, payloadBytes), data);
    file.push_back('x'); // one byte more than the header says
    EXPECT_NE(checkPipelineCacheFile(file, gpu.device.properties, &payload, &payloadBytes), "");
}
