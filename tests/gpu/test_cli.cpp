// The `shadel` command line as a user meets it: bad input gives one line on stderr naming the
// input and the reason and exit code 2 — never a crash or a hang.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace {

struct Result {
    int exitCode = -1;
    std::string stderrText;
};

Result run(const std::string& args) {
    std::string errFile =
        (std::filesystem::temp_directory_path() / "shadel_cli_stderr.txt").string();
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    Result r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    r.stderrText = ss.str();
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
          "--device 57 render", "render --jitter wobble",
          "render --mode decoupled --marking sideways"}) {
        Result r = run(args);
        EXPECT_EQ(r.exitCode, 2) << args << ": " << r.stderrText;
        EXPECT_NE(r.stderrText.find("shadel: "), std::string::npos) << args;
    }
}

TEST(Cli, RenderWritesPngAndStatsJson) {
    auto dir = std::filesystem::temp_directory_path() / "shadel_cli_out";
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
