#include "rhi/shader_reload.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "core/log.h"
#include "rhi/gpu.h"
#include "rhi/shader_messages.h"

namespace shadel {

namespace fs = std::filesystem;

struct PipelineRecord {
    bool compute = false;
    GraphicsPipelineDesc graphics;
    std::string computeName, computeShader;
    std::vector<std::pair<uint32_t, uint32_t>> specialization;
    Pipeline replacement; // null until a reload swapped it
};

struct ShaderHotReload {
    fs::path sourceDir;
    std::map<VkPipeline, PipelineRecord> pipelines;     // by the pipeline its owner holds
    std::map<std::string, std::vector<uint32_t>> spirv; // newest good code by .spv name
    std::map<std::string, std::pair<fs::file_time_type, uintmax_t>> files; // rel path -> stamp
    bool rebuilding = false;
};

namespace {

bool isShaderFile(const fs::path& p) {
    static const std::set<std::string> kinds = {".glsl", ".h",    ".vert", ".frag",
                                                ".comp", ".mesh", ".task"};
    return kinds.count(p.extension().string()) != 0;
}

std::map<std::string, std::pair<fs::file_time_type, uintmax_t>> scan(const fs::path& dir) {
    std::map<std::string, std::pair<fs::file_time_type, uintmax_t>> out;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
         it.increment(ec)) {
        if (!it->is_regular_file() || !isShaderFile(it->path())) continue;
        out[fs::relative(it->path(), dir).generic_string()] = {it->last_write_time(),
                                                               it->file_size()};
    }
    return out;
}

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// `rel` and everything it includes (textually: #include "x", resolved against the root).
void includeClosure(const fs::path& root, const std::string& rel, std::set<std::string>& out) {
    if (!out.insert(rel).second) return;
    std::istringstream in(readText(root / rel));
    std::string line;
    while (std::getline(in, line)) {
        size_t at = line.find("#include");
        if (at == std::string::npos) continue;
        size_t open = line.find('"', at), close = line.find('"', open + 1);
        if (open == std::string::npos || close == std::string::npos) continue;
        includeClosure(root, line.substr(open + 1, close - open - 1), out);
    }
}

// "forward/forward.frag" -> "forward_forward.frag.spv" (cmake/shaders.cmake's naming).
std::string spvName(const std::string& rel) {
    std::string flat = rel;
    for (char& c : flat)
        if (c == '/') c = '_';
    return flat + ".spv";
}

uint32_t shaderIdOf(const std::string& rel) {
    std::string want = "shaders/" + rel;
    for (uint32_t id = 1; id < 4096; ++id) {
        std::string name = shaderName(id);
        if (name == want) return id;
        if (name == "(unknown shader)") break;
    }
    return 0;
}

// Compiles one stage as the build does (cmake/shaders.cmake: glslc, Vulkan 1.3, -O, -Werror,
// includes from the root). Returns false with glslc's message ("post/tonemap.comp:27: error:
// ...") when it fails.
bool compileStage(const fs::path& root, const std::string& rel, std::vector<uint32_t>& spirv,
                  std::string& error) {
    fs::path tmp = fs::temp_directory_path() /
                   ("shadel-reload-" + std::to_string(::getpid()) + "-" + spvName(rel));
    fs::path log = tmp;
    log += ".log";
    std::string cmd = "cd '" + root.string() + "' && glslc --target-env=vulkan1.3 -O -I . " +
                      "-DSHADEL_SHADER_ID=" + std::to_string(shaderIdOf(rel)) + " -Werror -o '" +
                      tmp.string() + "' '" + rel + "' 2>'" + log.string() + "'";
    int status = std::system(cmd.c_str());
    bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (ok) {
        std::string bytes = readText(tmp);
        spirv.resize(bytes.size() / 4);
        std::memcpy(spirv.data(), bytes.data(), spirv.size() * 4);
        ok = !spirv.empty() && spirv[0] == 0x07230203u;
        if (!ok) error = rel + ": glslc wrote no SPIR-V";
    } else {
        error = readText(log);
        while (!error.empty() && error.back() == '\n') error.pop_back();
        if (error.empty()) error = rel + ": glslc failed (is it installed?)";
    }
    std::error_code ec;
    fs::remove(tmp, ec);
    fs::remove(log, ec);
    return ok;
}

} // namespace

void enableShaderHotReload(Gpu& gpu, const std::string& sourceDir) {
    if (!fs::is_directory(sourceDir))
        throw InputError(format("%s: no shader source folder to watch", sourceDir.c_str()));
    auto reload = std::make_shared<ShaderHotReload>();
    reload->sourceDir = sourceDir;
    reload->files = scan(sourceDir);
    gpu.hotReload = reload;
}

void disableShaderHotReload(Gpu& gpu) {
    if (!gpu.hotReload) return;
    vkDeviceWaitIdle(gpu.device.device);
    for (auto& [original, record] : gpu.hotReload->pipelines)
        if (record.replacement.pipeline) destroy(gpu, record.replacement);
    gpu.hotReload.reset();
}

void recordPipeline(Gpu& gpu, const Pipeline& pipeline, const GraphicsPipelineDesc* graphics,
                    const std::string& computeShader,
                    const std::vector<std::pair<uint32_t, uint32_t>>& specialization) {
    if (!gpu.hotReload || gpu.hotReload->rebuilding) return;
    PipelineRecord r;
    r.compute = graphics == nullptr;
    if (graphics) r.graphics = *graphics;
    r.computeName = pipeline.name;
    r.computeShader = computeShader;
    r.specialization = specialization;
    gpu.hotReload->pipelines[pipeline.pipeline] = std::move(r);
}

VkPipeline currentPipeline(const Gpu& gpu, VkPipeline original) {
    if (!gpu.hotReload) return original;
    auto it = gpu.hotReload->pipelines.find(original);
    if (it == gpu.hotReload->pipelines.end() || !it->second.replacement.pipeline) return original;
    return it->second.replacement.pipeline;
}

void forgetPipeline(Gpu& gpu, VkPipeline original) {
    if (!gpu.hotReload) return;
    auto it = gpu.hotReload->pipelines.find(original);
    if (it == gpu.hotReload->pipelines.end()) return;
    if (it->second.replacement.pipeline) destroy(gpu, it->second.replacement);
    gpu.hotReload->pipelines.erase(it);
}

const std::vector<uint32_t>* reloadedSpirv(const Gpu& gpu, const std::string& name) {
    if (!gpu.hotReload) return nullptr;
    auto it = gpu.hotReload->spirv.find(name);
    return it == gpu.hotReload->spirv.end() ? nullptr : &it->second;
}

ShaderReloadResult pollShaderReload(Gpu& gpu) {
    ShaderReloadResult result;
    if (!gpu.hotReload) return result;
    ShaderHotReload& h = *gpu.hotReload;
    auto now = scan(h.sourceDir);
    std::set<std::string> changed;
    for (auto& [rel, stamp] : now) {
        auto it = h.files.find(rel);
        if (it == h.files.end() || it->second != stamp) changed.insert(rel);
    }
    h.files = std::move(now);
    if (changed.empty()) return result;

    // The stages live pipelines use, by source path.
    std::set<std::string> stages;
    for (auto& [original, r] : h.pipelines) {
        for (const std::string& spv :
             {r.graphics.vertexShader, r.graphics.fragmentShader, r.computeShader})
            if (!spv.empty()) stages.insert(spv);
    }
    std::map<std::string, std::string> sourceOfSpv; // spv name -> rel source
    for (auto& [rel, stamp] : h.files) {
        std::string ext = fs::path(rel).extension().string();
        if (ext != ".glsl" && ext != ".h") sourceOfSpv[spvName(rel)] = rel;
    }

    std::set<std::string> rebuilt; // spv names with new code
    for (const std::string& spv : stages) {
        auto src = sourceOfSpv.find(spv);
        if (src == sourceOfSpv.end()) continue;
        std::set<std::string> closure;
        includeClosure(h.sourceDir, src->second, closure);
        bool touched = false;
        for (const std::string& f : closure) touched = touched || changed.count(f);
        if (!touched) continue;
        std::vector<uint32_t> code;
        std::string message;
        if (!compileStage(h.sourceDir, src->second, code, message)) {
            SHADEL_ERROR("shader reload: %s (the last good pipeline stays)", message.c_str());
            result.errors.push_back(message);
            continue;
        }
        h.spirv[spv] = std::move(code);
        rebuilt.insert(spv);
        result.stagesRecompiled.push_back(src->second);
    }
    if (rebuilt.empty()) return result;

    vkDeviceWaitIdle(gpu.device.device); // replaced pipelines may still be in flight
    h.rebuilding = true;
    for (auto& [original, r] : h.pipelines) {
        bool uses = rebuilt.count(r.graphics.vertexShader) ||
                    rebuilt.count(r.graphics.fragmentShader) || rebuilt.count(r.computeShader);
        if (!uses) continue;
        try {
            Pipeline fresh = r.compute ? createComputePipeline(gpu, r.computeName, r.computeShader,
                                                               r.specialization)
                                       : createGraphicsPipeline(gpu, r.graphics);
            if (r.replacement.pipeline) destroy(gpu, r.replacement);
            r.replacement = fresh;
            ++result.pipelinesSwapped;
        } catch (const std::exception& e) {
            result.errors.push_back(e.what());
        }
    }
    h.rebuilding = false;
    SHADEL_INFO("shader reload: %zu stage(s) recompiled, %u pipeline(s) swapped",
                result.stagesRecompiled.size(), result.pipelinesSwapped);
    return result;
}

} // namespace shadel
