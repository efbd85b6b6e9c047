// The `shadel` command line as a user meets it: bad input gives one line on stderr naming the
// input and the reason and exit code 2 — never a crash or a hang.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "gpu_test_env.h"

#include "core/host.h"
#include "core/log.h"

using shadel::format;
using shadel::HostInfo;
using shadel::hostInfo;
using shadel::test::sharedGpu;
using shadel::test::tempPath;

namespace {

struct Result {
    int exitCode = -1;
    std::string stderrText;
};

struct Output {
    int exitCode = -1;
    std::string stdoutText, stderrText;
};

std::string readText(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Where a command's streams go (private to this test process).
std::string streamFile(const char* name) {
    return tempPath(std::string("cli_") + name + ".txt");
}

// Runs `env` (e.g. "XDG_CACHE_HOME=") shadel `args`, keeping both streams.
Output runWithEnv(const std::string& env, const std::string& args) {
    std::string outFile = streamFile("stdout");
    std::string errFile = streamFile("stderr");
    std::string cmd = "env " + env + " timeout 120 " + SHADEL_BINARY + " " + args + " >" + outFile +
                      " 2>" + errFile;
    int status = std::system(cmd.c_str());
    Output o;
    o.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.stdoutText = readText(outFile);
    o.stderrText = readText(errFile);
    std::filesystem::remove(outFile);
    std::filesystem::remove(errFile);
    return o;
}

Result run(const std::string& args) {
    std::string errFile = streamFile("stderr");
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    Result r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    r.stderrText = ss.str();
    in.close();
    std::filesystem::remove(errFile);
    return r;
}

// Warnings (graceful degradation) may precede the error; the error is the last line.
std::string lastLine(const std::string& text) {
    std::string t = text;
    while (!t.empty() && t.back() == '\n') t.pop_back();
    size_t nl = t.rfind('\n');
    return nl == std::string::npos ? t : t.substr(nl + 1);
}

} // namespace

TEST(Cli, EveryMalformedGltfIsOneErrorLineAndExitCode2) {
    std::string dir = std::string(SHADEL_SOURCE_DIR) + "/tests/data/bad";
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        std::string ext = entry.path().extension().string();
        if (ext != ".gltf" && ext != ".glb") continue;
        ++files;
        Result r = run("render --size 32x32 --scene " + entry.path().string());
        EXPECT_EQ(r.exitCode, 2) << entry.path() << ": " << r.stderrText;
        std::string line = lastLine(r.stderrText);
        EXPECT_NE(line.find(entry.path().filename().string()), std::string::npos)
            << "the error must name the file: " << line;
        EXPECT_EQ(line.rfind("shadel: ", 0), 0u) << line;
    }
    EXPECT_GT(files, 10);
}

TEST(Cli, BadFlagsAndMissingFilesExitWith2) {
    for (const std::string args :
         {"render --scene /nonexistent/scene.gltf", "render --scene builtin:nope",
          "render --size 0x10", "render --size banana", "render --size 99999x10",
          "render --mode sideways", "render --visualize everything",
          "render --camera nope --size 16x16", "render --frames 0", "render --ssaa 0",
          "--device 57 render", "render --jitter wobble", "render --density -3",
          "render --density lots", "render --mode decoupled --marking sideways",
          "render --size 16x16 --mode decoupled --material-samples 0",
          "render --size 16x16 --oit layered", "render --size 16x16 --shuffle-draws banana"}) {
        Result r = run(args);
        EXPECT_EQ(r.exitCode, 2) << args << ": " << r.stderrText;
        EXPECT_NE(r.stderrText.find("shadel: "), std::string::npos) << args;
    }
}

TEST(Cli, RenderWritesPngAndStatsJson) {
    std::filesystem::path dir = tempPath("cli_out");
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    Result r = run("render --size 48x32 --frames 2 --out " + (dir / "frames/").string() +
                   " --stats " + (dir / "s.json").string());
    EXPECT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_TRUE(std::filesystem::exists(dir / "frames/frame_0000.png"));
    EXPECT_TRUE(std::filesystem::exists(dir / "frames/frame_0001.png"));
    std::ifstream in(dir / "s.json");
    std::stringstream ss;
    ss << in.rdbuf();
    for (const char* key :
         {"\"device\"", "\"mode\"", "\"frame_ms\"", "\"passes\"", "\"pixels_covered\"",
          "\"shadels_per_pixel\"", "\"reconstruction_misses\"", "\"validation_errors\""})
        EXPECT_NE(ss.str().find(key), std::string::npos) << key;
}

// --- every command-line error is one line and exit code 2 ------------------------

namespace {

size_t lineCount(const std::string& text) {
    return size_t(std::count(text.begin(), text.end(), '\n'));
}

// `args` fails as bad input must: exit code 2 and one "shadel: " line on stderr naming `named`.
void expectOneLineError(const std::string& args, const std::string& named) {
    Result r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.stderrText;
    EXPECT_EQ(lineCount(r.stderrText), 1u) << args << ": " << r.stderrText;
    EXPECT_EQ(r.stderrText.rfind("shadel: ", 0), 0u) << args << ": " << r.stderrText;
    EXPECT_NE(r.stderrText.find(named), std::string::npos) << args << ": " << r.stderrText;
}

// A scratch folder per test, removed afterwards.
struct CliTempDir {
    CliTempDir() {
        path = tempPath(
            "cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~CliTempDir() { std::filesystem::remove_all(path); }
    std::string file(const std::string& name) const { return (path / name).string(); }
    size_t entries() const {
        return size_t(std::distance(std::filesystem::directory_iterator(path),
                                    std::filesystem::directory_iterator()));
    }
    std::filesystem::path path;
};

} // namespace

// The parser's own errors used CLI11's exit codes (109, 106, 105) and a two-line message.
TEST(Cli, ParserErrorsAreOneLineAndExitCode2) {
    const std::pair<const char*, const char*> cases[] = {
        {"render --no-such-flag", "--no-such-flag"},
        {"render --frames -1", "--frames"},
        {"render --frames abc", "--frames"},
        {"", "subcommand"},
        {"paint", "subcommand"},
        {"bench --frames x", "--frames"},
        {"bench --interleave sometimes", "--interleave"},
        {"bench --interleave 0", "--interleave"},
    };
    for (auto [args, named] : cases) expectOneLineError(args, named);
}

// NaN, infinity and out-of-range floats used to render black or garbage with exit code 0.
TEST(Cli, FloatFlagsMustBeFiniteAndInRange) {
    const std::pair<const char*, const char*> cases[] = {
        {"render --exposure nan", "--exposure"},
        {"render --exposure 21", "--exposure"}, // EV: 2^21 is beyond the range
        {"render --exposure inf", "--exposure"},
        {"render --shading-bias nan", "--shading-bias"},
        {"render --shading-bias 1e30", "--shading-bias"},
        {"render --trilinear-band -1", "--trilinear-band"},
        {"render --trilinear-band 1.5", "--trilinear-band"},
        {"render --density nan", "--density"},
        {"render --density -3", "--density"},
        {"render --shadel-budget nan", "--shadel-budget"},
        {"render --forward-below nan", "--forward-below"},
        {"render --forward-below -1", "--forward-below"},
        {"bench --density nan", "--density"},
        {"bake --density inf builtin:smooth", "--density"},
        {"bake --shadel-budget 0 builtin:smooth", "--shadel-budget"},
    };
    for (auto [args, flag] : cases) expectOneLineError(args, flag); // names the flag
}

// The image-based lighting, tone curve, background, shadow and sun options: a bad value is one
// line naming the option (before the scene is loaded: the scene here does not exist).
TEST(Cli, EnvironmentToneAndBackgroundOptionsRejectBadValues) {
    const std::pair<const char*, const char*> cases[] = {
        {"render --scene /nonexistent.gltf --environment /nonexistent/sky.hdr",
         "--environment /nonexistent/sky.hdr: no such file"},
        {"render --scene /nonexistent.gltf --environment sky.png",
         "--environment sky.png: expected builtin:sky, none or an equirectangular .hdr"},
        {"render --scene /nonexistent.gltf --environment-intensity -1",
         "--environment-intensity -1"},
        {"render --scene /nonexistent.gltf --environment-intensity nan",
         "--environment-intensity nan"},
        {"render --scene /nonexistent.gltf --environment-rotation inf",
         "--environment-rotation inf"},
        {"render --scene /nonexistent.gltf --tonemap sepia",
         "--tonemap sepia: expected aces-narkowicz, aces-hill, khr-pbr-neutral or linear"},
        {"render --scene /nonexistent.gltf --background 2,0,0", "--background 2,0,0"},
        {"render --scene /nonexistent.gltf --background red", "--background red"},
        {"render --scene /nonexistent.gltf --shadows maybe", "--shadows maybe: expected on or off"},
        {"render --scene /nonexistent.gltf --sun sometimes",
         "--sun sometimes: expected auto or off"},
        {"bench --scene /nonexistent.gltf --tonemap sepia", "--tonemap sepia"},
        {"view --scene /nonexistent.gltf --exposure nan", "--exposure nan"},
    };
    for (auto [args, message] : cases) expectOneLineError(args, message);
}

// The stats echo every option of the table as the run was asked for it: --exposure in EV, the
// tone curve and background by name, on/off options as booleans.
TEST(Cli, StatsEchoTheSettingsAsGiven) {
    CliTempDir dir;
    Output o = runWithEnv("", "render --size 32x18 --exposure 1.5 --tonemap khr-pbr-neutral "
                              "--background 0.25,0.5,1 --shadows off --sun off --stats " +
                                  dir.file("s.json"));
    ASSERT_EQ(o.exitCode, 0) << o.stderrText;
    nlohmann::json settings = nlohmann::json::parse(readText(dir.file("s.json")))["settings"];
    EXPECT_NEAR(settings["exposure"].get<double>(), 1.5, 1e-6); // through a float 2^EV
    EXPECT_EQ(settings["tonemap"], "khr-pbr-neutral");
    EXPECT_EQ(settings["background"], nlohmann::json({0.25, 0.5, 1.0}));
    EXPECT_EQ(settings["shadows"], false);
    EXPECT_EQ(settings["sun"], false);
    EXPECT_EQ(settings["environment"], "builtin:sky");
    EXPECT_EQ(settings["material-samples"], 16);
    EXPECT_EQ(settings["size"], nlohmann::json({32, 18}));
}

// OVERVIEW documents --forward-below; it was rejected as unknown.
TEST(Cli, ForwardBelowIsAFlag) {
    CliTempDir dir;
    Result r =
        run("render --mode decoupled --size 32x32 --forward-below 0 --stats " + dir.file("s.json"));
    EXPECT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_TRUE(std::filesystem::exists(dir.file("s.json")));
}

// A decoupled render's summary says what it is judged by: shadels per covered pixel, misses
// and, with reuse over several frames, what was carried over and why the rest was shaded; the
// figures are the stats file's.
TEST(Cli, DecoupledSummaryGivesShadelsPerPixelAndReuse) {
    CliTempDir dir;
    Output o = runWithEnv("", "render --mode decoupled --size 64x36 --frames 3 --camera-path "
                              "orbit --stats " +
                                  dir.file("s.json"));
    ASSERT_EQ(o.exitCode, 0) << o.stderrText;
    nlohmann::json stats = nlohmann::json::parse(readText(dir.file("s.json")));
    std::string perPixel =
        format("%.2f shadels per covered pixel", stats["shadels_per_pixel"].get<double>());
    std::string carried = format("%.1f%% of stored shadels carried over",
                                 100.0 * stats["reuse_fraction"].get<double>());
    EXPECT_NE(o.stdoutText.find(perPixel), std::string::npos) << o.stdoutText;
    EXPECT_NE(o.stdoutText.find(carried), std::string::npos) << o.stdoutText;
    EXPECT_NE(o.stdoutText.find("shaded for"), std::string::npos) << o.stdoutText;
    Output forward = runWithEnv("", "render --size 64x36");
    EXPECT_EQ(forward.stdoutText.find("shadels per covered pixel"), std::string::npos);
}

// On a software device every timing is the host CPU's: the stats name it.
TEST(Cli, StatsNameTheDeviceAndTheHostCpu) {
    CliTempDir dir;
    Output o = runWithEnv("", "render --size 32x18 --stats " + dir.file("s.json"));
    ASSERT_EQ(o.exitCode, 0) << o.stderrText;
    nlohmann::json stats = nlohmann::json::parse(readText(dir.file("s.json")));
    HostInfo host = hostInfo();
    EXPECT_EQ(stats["device"], sharedGpu().device.name);
    EXPECT_EQ(stats["host"]["cpu"], host.cpu);
    EXPECT_EQ(stats["host"]["threads"], host.threads);
}

TEST(Cli, SubcommandHelpShowsGlobalFlagsAndTheBakeCache) {
    for (const char* sub : {"render", "bench", "bake", "info", "cache", "cache clean"}) {
        Output o = runWithEnv("SHADEL_CACHE_DIR=/tmp/some-cache", std::string(sub) + " --help");
        EXPECT_EQ(o.exitCode, 0) << sub << ": " << o.stderrText;
        for (const char* global : {"--device", "--validation", "--verbose",
                                   "--allow-external-files", "Cache folder: /tmp/some-cache"})
            EXPECT_NE(o.stdoutText.find(global), std::string::npos) << sub << " --help: " << global;
    }
    // ... and they are accepted after the subcommand too.
    Result r = run("render --size 16x16 --device cpu");
    EXPECT_EQ(r.exitCode, 0) << r.stderrText;
}

// --- every write is checked ------------------------------------------------------------------

TEST(Cli, FullDeviceFailsTheRenderWithOneLine) {
    for (const char* flag : {"--out", "--stats"}) {
        Result r = run(std::string("render --size 16x16 ") + flag + " /dev/full");
        EXPECT_NE(r.exitCode, 0) << flag;
        EXPECT_EQ(lastLine(r.stderrText), "shadel: cannot write /dev/full: No space left on device")
            << flag << ": " << r.stderrText;
    }
    Result bench = run("bench --size 16x16 --frames 1 --json /dev/full");
    EXPECT_NE(bench.exitCode, 0);
    EXPECT_EQ(lastLine(bench.stderrText), "shadel: cannot write /dev/full: No space left on device")
        << bench.stderrText;
}

// Outputs are checked before the scene is even loaded (the scene here does not exist).
TEST(Cli, UncreatableOutputsFailBeforeRendering) {
    CliTempDir dir;
    std::string missing = dir.file("no/such/folder/x");
    const std::pair<std::string, std::string> cases[] = {
        {"render --scene /nonexistent.gltf --out " + missing + ".png", "--out " + missing + ".png"},
        {"render --scene /nonexistent.gltf --stats " + missing + ".json",
         "--stats " + missing + ".json"},
        {"render --scene /nonexistent.gltf --stats " + dir.path.string(),
         "--stats " + dir.path.string() + ": Is a directory"},
        {"bench --scene /nonexistent.gltf --json " + missing + ".json",
         "--json " + missing + ".json"},
    };
    for (const auto& [args, message] : cases) expectOneLineError(args, message);
    EXPECT_EQ(dir.entries(), 0u) << "nothing may be left behind";
}

// Outputs that would block (a FIFO nobody reads) or clobber each other (one path for two
// outputs, also through "./"), and numbers that would wrap, are one line and exit 2 before any
// work; the scene here does not exist, so the error must come first.
TEST(Cli, BlockingCollidingOrWrappingOutputsFailBeforeRendering) {
    CliTempDir dir;
    std::string fifo = dir.file("frame.png");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
    std::string same = dir.file("same.png");
    std::string sameAgain = dir.path.string() + "/./same.png";
    const std::pair<std::string, std::string> cases[] = {
        {"render --scene /nonexistent.gltf --out " + fifo,
         "--out " + fifo + ": a FIFO, not a file"},
        {"render --scene /nonexistent.gltf --out " + same + " --stats " + sameAgain,
         "--stats " + sameAgain + ": the same file as --out"},
        {"bench --scene /nonexistent.gltf --json " + same + " --plot " + same,
         "--plot " + same + ": the same file as --json"},
        {"render --scene /nonexistent.gltf --size 4294967616x4294967476",
         "--size 4294967616x4294967476: each side must be between 1 and 16384"},
        {"render --scene /nonexistent.gltf --size 99999999999999999999999x9",
         "--size 99999999999999999999999x9: expected WIDTHxHEIGHT"},
        {"render --scene /nonexistent.gltf --out " + dir.file("frame.jpg"),
         "frame.jpg: '.jpg' is not an image format shadel writes: .png or .exr"},
        {"render --scene /nonexistent.gltf --out " + dir.file("frame"),
         "frame: no file extension: .png (display colours) or .exr (scene-linear HDR)"},
    };
    for (const auto& [args, message] : cases) expectOneLineError(args, message);
    EXPECT_EQ(dir.entries(), 1u) << "only the FIFO: nothing written";
}

// Small files whose cost must stay linear: a 1 MB strip of a million copies of one triangle
// (automatic framing marks each grid cell once; vertex-cache optimization is skipped at high
// valence; repeated triangles are drawn once) and a grid of 100k instances. Each renders well
// within the harness's 120 s timeout (3.5 s and 4.6 s on a 2-core lavapipe machine); the strip
// is drawn as its two faces.
TEST(Cli, HostileGeometryRendersInLinearTime) {
    CliTempDir dir;
    const uint32_t copies = 1000000;
    {
        const float p[9] = {-1, -1, 0, 1, -1, 0, 0, 1, 0};
        std::ofstream bin(dir.file("strip.bin"), std::ios::binary);
        bin.write(reinterpret_cast<const char*>(p), sizeof p);
        for (uint32_t i = 0; i < copies; ++i) bin.put(char(i % 3));
    }
    auto gltf = [&](const std::string& nodes, const std::string& sceneNodes,
                    const std::string& primitive) {
        return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":)" + sceneNodes +
               R"(}],"nodes":)" + nodes + R"(,"meshes":[{"primitives":[)" + primitive +
               R"(]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
               "min":[-1,-1,0],"max":[1,1,0]},{"bufferView":1,"componentType":5121,"count":)" +
               std::to_string(copies) + R"(,"type":"SCALAR"}],"bufferViews":[{"buffer":0,
               "byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":)" +
               std::to_string(copies) + R"(}],"buffers":[{"uri":"strip.bin","byteLength":)" +
               std::to_string(36 + copies) + "}]}";
    };
    std::ofstream(dir.file("strip.gltf"))
        << gltf(R"([{"mesh":0}])", "[0]", R"({"attributes":{"POSITION":0},"indices":1,"mode":5})");
    std::string nodes = "[", sceneNodes = "[";
    for (int i = 0; i < 100000; ++i) {
        if (i) nodes += ',', sceneNodes += ',';
        nodes += format(R"({"mesh":0,"translation":[%d,0,%d]})", i % 316 * 2, i / 316 * 2);
        sceneNodes += std::to_string(i);
    }
    std::ofstream(dir.file("grid.gltf"))
        << gltf(nodes + "]", sceneNodes + "]", R"({"attributes":{"POSITION":0}})");

    Result strip = run("render --size 32x32 --scene " + dir.file("strip.gltf"));
    EXPECT_EQ(strip.exitCode, 0) << strip.stderrText;
    EXPECT_NE(strip.stderrText.find("999996 triangles repeat an earlier one"), std::string::npos)
        << strip.stderrText;
    Result grid = run("render --size 32x32 --scene " + dir.file("grid.gltf"));
    EXPECT_EQ(grid.exitCode, 0) << grid.stderrText;
}

// Cache entries are written whole or not at all: two bakes sharing one folder at once, and a
// bake killed with SIGKILL midway, leave only whole entries, and the next run uses every one
// (a torn or interleaved entry would fail its checksum and be rebaked, with a warning).
TEST(Cli, ConcurrentAndKilledBakesLeaveOnlyWholeEntries) {
    CliTempDir dir;
    std::string bake = std::string(SHADEL_BINARY) + " bake builtin:default --cache-dir ";
    auto shell = [](const std::string& command) {
        int status = std::system(command.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    };
    std::string shared = dir.file("shared");
    std::string both;
    for (const char* rc : {"a.rc", "b.rc"})
        both += format("(%s%s >/dev/null 2>&1; echo $? >%s) & ", bake.c_str(), shared.c_str(),
                       dir.file(rc).c_str());
    ASSERT_EQ(shell(both + "wait"), 0);
    EXPECT_EQ(readText(dir.file("a.rc")), "0\n");
    EXPECT_EQ(readText(dir.file("b.rc")), "0\n");
    Output again = runWithEnv("", "bake builtin:default --cache-dir " + shared);
    EXPECT_EQ(again.exitCode, 0) << again.stderrText;
    EXPECT_NE(again.stdoutText.find("meshes: 132 (132 from cache)"), std::string::npos)
        << again.stdoutText << again.stderrText;

    std::string killed = dir.file("killed");
    // Killed a second into a bake of several seconds: some entries written, one maybe half.
    shell(bake + killed + " >/dev/null 2>&1 & pid=$!; sleep 1.5; kill -9 $pid; wait $pid");
    Output fresh = runWithEnv("", "bake builtin:default --cache-dir " + killed);
    EXPECT_EQ(fresh.exitCode, 0) << fresh.stderrText;
    EXPECT_EQ(fresh.stderrText.find("rebaking"), std::string::npos)
        << "no entry may be torn: " << fresh.stderrText;
    Output used = runWithEnv("", "bake builtin:default --cache-dir " + killed);
    EXPECT_NE(used.stdoutText.find("meshes: 132 (132 from cache)"), std::string::npos)
        << used.stdoutText << used.stderrText;
}

// Options that contradict each other are errors before the scene is loaded and baked (the
// scene here does not exist: the error must name the options, not the file).
TEST(Cli, InconsistentOptionsFailBeforeLoading) {
    const std::pair<const char*, const char*> cases[] = {
        {"render --scene /nonexistent.gltf --visualize gi", "--visualize gi"},
        {"render --scene /nonexistent.gltf --visualize tiles", "--visualize tiles"},
        {"render --scene /nonexistent.gltf --visualize reuse", "--visualize reuse"},
        {"render --scene /nonexistent.gltf --distance-fields on", "--distance-fields on"},
        {"render --scene /nonexistent.gltf --material-samples 0", "--material-samples 0"},
        {"render --scene /nonexistent.gltf --gi lpv --gi-iterations 99", "--gi-iterations 99"},
    };
    for (auto [args, message] : cases) expectOneLineError(args, message);
}

// --- the bake cache location and glTF URIs ----------------------------------------------------

// XDG_CACHE_HOME="" put the cache at /shadel; an empty or relative value must be ignored.
TEST(Cli, EmptyOrRelativeXdgCacheHomeIsIgnored) {
    for (const char* xdg : {"XDG_CACHE_HOME=", "XDG_CACHE_HOME=relative/cache"}) {
        Output o = runWithEnv(std::string("-u SHADEL_CACHE_DIR ") + xdg + " HOME=/home/someone",
                              "render --help");
        EXPECT_EQ(o.exitCode, 0);
        EXPECT_NE(o.stdoutText.find("Cache folder: /home/someone/.cache/shadel"), std::string::npos)
            << xdg << ": " << o.stdoutText;
    }
    Output o = runWithEnv("-u SHADEL_CACHE_DIR XDG_CACHE_HOME=/xdg", "bake --help");
    EXPECT_NE(o.stdoutText.find("Cache folder: /xdg/shadel"), std::string::npos) << o.stdoutText;
}

TEST(Cli, InfoShowsTheBakeCache) {
    Output o = runWithEnv("SHADEL_CACHE_DIR=/tmp/info-cache", "info");
    EXPECT_EQ(o.exitCode, 0) << o.stderrText;
    EXPECT_NE(o.stdoutText.find("cache folder: /tmp/info-cache"), std::string::npos)
        << o.stdoutText;
}

// A buffer URI ../../../../etc/passwd was read (absolute paths were already refused).
TEST(Cli, BufferUriOutsideTheModelFolderIsRefused) {
    CliTempDir dir;
    std::string model = dir.file("escape.gltf");
    std::ofstream(model) << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],
        "nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"uri":"../../../../etc/passwd","byteLength":36}]})";
    Result r = run("render --size 16x16 --scene " + model);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(lastLine(r.stderrText),
              "shadel: " + model +
                  ": /buffers/0/uri '../../../../etc/passwd' points outside the model's folder "
                  "(--allow-external-files allows it)");
    // With the flag the URI is followed (and the text file is then not a valid buffer).
    Result allowed = run("--allow-external-files render --size 16x16 --scene " + model);
    EXPECT_EQ(allowed.stderrText.find("outside the model's folder"), std::string::npos)
        << allowed.stderrText;
}

// OVERVIEW documented --forward-below, which did not exist: every flag the docs name must be in
// some command's --help.
TEST(Cli, EveryDocumentedFlagExists) {
    std::string help;
    for (const char* sub : {"render", "bench", "bake", "info", "view"})
        help += runWithEnv("", std::string(sub) + " --help").stdoutText;
    int flags = 0;
    for (const char* doc : {"/README.md", "/OVERVIEW.md"}) {
        std::string text = readText(std::string(SHADEL_SOURCE_DIR) + doc);
        for (size_t at = text.find("--"); at != std::string::npos; at = text.find("--", at + 2)) {
            size_t end = at + 2;
            while (end < text.size() &&
                   (std::islower(static_cast<unsigned char>(text[end])) ||
                    std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '-'))
                ++end;
            if (end == at + 2 || !std::islower(static_cast<unsigned char>(text[at + 2]))) continue;
            std::string flag = text.substr(at, end - at);
            while (flag.back() == '-') flag.pop_back();
            ++flags;
            EXPECT_NE(help.find(flag), std::string::npos) << doc << " documents " << flag;
        }
    }
    EXPECT_GT(flags, 10);
}

TEST(Cli, CacheCommandShowsAndCleansTheCache) {
    CliTempDir dir;
    std::string cache = dir.file("cache");
    Output baked = runWithEnv("", "bake builtin:smooth --cache-dir " + cache);
    ASSERT_EQ(baked.exitCode, 0) << baked.stderrText;
    std::string files = std::to_string(std::distance(std::filesystem::directory_iterator(cache),
                                                     std::filesystem::directory_iterator())) +
                        " files";
    ASSERT_NE(files, "0 files");
    Output shown = runWithEnv("SHADEL_CACHE_DIR=" + cache, "cache");
    EXPECT_EQ(shown.exitCode, 0) << shown.stderrText;
    EXPECT_NE(shown.stdoutText.find("cache: " + cache + "\n" + files), std::string::npos)
        << shown.stdoutText;
    Output cleaned = runWithEnv("", "cache clean --cache-dir " + cache);
    EXPECT_EQ(cleaned.exitCode, 0) << cleaned.stderrText;
    EXPECT_NE(cleaned.stdoutText.find("removed " + files), std::string::npos) << cleaned.stdoutText;
    EXPECT_TRUE(std::filesystem::is_empty(cache));
    Result bad = run("--cache-limit lots cache");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.stderrText.find("--cache-limit"), std::string::npos) << bad.stderrText;
}
