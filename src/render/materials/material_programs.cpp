#include "render/materials/material_programs.h"

#include <cstring>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "materials/program_types.h"
#include "render/gpu_scene.h"
#include "render/materials/material_program.h"
#include "rhi/pipeline_spirv.h"

namespace shadel {

// A program's files as last loaded: path -> (time stamp, size).
using ProgramFileStamps =
    std::map<std::string, std::pair<std::filesystem::file_time_type, uintmax_t>>;

struct MaterialProgramSet {
    std::vector<MaterialProgram> programs;
    std::vector<ProgramFileStamps> stamps;     // per program
    std::vector<std::vector<Pipeline>> stages; // per program, in order
    std::vector<uint32_t> programOfMaterial;   // 0: built-in, k: programs[k - 1]
    Pipeline setup;                            // materials/program_setup.comp
    BufferHandle header;                       // MATERIAL_LIST_HEADER_BYTES, read back
    BufferHandle queues;                       // per program, capacity entries
    uint32_t capacity = 0;
    // Chunks each program's list held, summed over the frames finished (index 0: built-in).
    std::vector<uint64_t> chunks;
    uint64_t frames = 0;
};

void MaterialProgramSetDeleter::operator()(MaterialProgramSet* set) const {
    delete set;
}

namespace {

struct ListsSetupPush {
    uint64_t header;
    uint32_t programs;
};
struct StagePush {
    uint64_t frame, header, queues;
    uint32_t program, capacity;
};

ProgramFileStamps fileStamps(const MaterialProgram& program) {
    ProgramFileStamps out;
    std::vector<std::string> files = {program.path};
    if (!program.common.empty()) files.push_back(program.common);
    for (const MaterialStage& s : program.stages) files.push_back(s.path);
    for (const std::string& f : files) {
        std::error_code ec;
        auto time = std::filesystem::last_write_time(f, ec);
        uintmax_t size = ec ? 0 : std::filesystem::file_size(f, ec);
        out[f] = {time, size};
    }
    return out;
}

// Loads and compiles the program in `file` into pipelines named after it.
std::vector<Pipeline> buildProgram(Gpu& gpu, const std::string& file, MaterialProgram& program) {
    program = loadMaterialProgram(file);
    std::vector<std::vector<uint32_t>> code =
        compileMaterialProgram(program, SHADEL_SHADER_SOURCE_DIR);
    std::vector<Pipeline> pipelines;
    for (size_t s = 0; s < code.size(); ++s)
        pipelines.push_back(createComputePipelineFromSpirv(
            gpu, "material." + program.name + "." + program.stages[s].name, code[s]));
    return pipelines;
}

void loadPrograms(Gpu& gpu, const GpuScene& scene, MaterialProgramSet& set) {
    std::map<std::string, uint32_t> byFile; // resolved .shmat -> its program number (1-based)
    set.programOfMaterial.assign(scene.materialInfo.size(), 0u);
    for (size_t m = 0; m < scene.materialPrograms.size() && m < set.programOfMaterial.size(); ++m) {
        const std::string& reference = scene.materialPrograms[m];
        if (reference.empty()) continue;
        std::string file = materialProgramFile(reference);
        auto known = byFile.find(file);
        if (known == byFile.end()) {
            if (set.programs.size() == MATERIAL_MAX_PROGRAMS)
                throw InputError(format("%s: more than %u material programs in one scene",
                                        file.c_str(), MATERIAL_MAX_PROGRAMS));
            MaterialProgram program;
            std::vector<Pipeline> pipelines = buildProgram(gpu, file, program);
            set.stamps.push_back(fileStamps(program));
            set.programs.push_back(std::move(program));
            set.stages.push_back(std::move(pipelines));
            known = byFile.emplace(file, uint32_t(set.programs.size())).first;
        }
        set.programOfMaterial[m] = known->second;
    }
}

} // namespace

MaterialProgramSetPtr createMaterialPrograms(Gpu& gpu, const GpuScene& scene,
                                             uint32_t capacityChunks) {
    MaterialProgramSetPtr set(new MaterialProgramSet());
    set->capacity = capacityChunks;
    try {
        loadPrograms(gpu, scene, *set);
    } catch (...) {
        destroyMaterialPrograms(gpu, set);
        throw;
    }
    set->chunks.assign(set->programs.size() + 1, 0);
    if (set->programs.empty()) return set;
    set->setup =
        createComputePipeline(gpu, "materialProgramSetup", "materials_program_setup.comp.spv");
    set->header =
        createBuffer(gpu, {"materials.programHeader", MATERIAL_LIST_HEADER_BYTES,
                           VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                           MemoryKind::Readback});
    set->queues = createBuffer(gpu, {"materials.programQueues",
                                     VkDeviceSize(capacityChunks) * set->programs.size() * 4, 0,
                                     MemoryKind::DeviceLocal});
    if (!set->header || !set->queues) {
        destroyMaterialPrograms(gpu, set);
        throw DeviceError("out of GPU memory for the material program lists");
    }
    std::memset(mapped(gpu, set->header), 0, MATERIAL_LIST_HEADER_BYTES);
    SHADEL_INFO("material programs: %zu loaded", set->programs.size());
    return set;
}

void destroyMaterialPrograms(Gpu& gpu, MaterialProgramSetPtr& set) {
    if (!set) return;
    for (std::vector<Pipeline>& stages : set->stages)
        for (Pipeline& p : stages) destroy(gpu, p);
    if (set->setup.pipeline) destroy(gpu, set->setup);
    if (set->header) destroy(gpu, set->header);
    if (set->queues) destroy(gpu, set->queues);
    set.reset();
}

uint32_t materialProgramFlags(const MaterialProgramSet* set, uint32_t material) {
    if (!set || material >= set->programOfMaterial.size()) return 0u;
    uint32_t program = set->programOfMaterial[material];
    bool everyFrame = program != 0 && set->programs[program - 1].everyFrame;
    return (program << SHADEL_OBJECT_PROGRAM_SHIFT) |
           (everyFrame ? SHADEL_OBJECT_PROGRAM_EVERY_FRAME : 0u);
}

ProgramListsPush programListsPush(const Gpu& gpu, const MaterialProgramSet* set, uint64_t frame) {
    ProgramListsPush push;
    push.frame = frame;
    if (set && !set->programs.empty()) {
        push.header = address(gpu, set->header);
        push.queues = address(gpu, set->queues);
    }
    return push;
}

void recordProgramListsClear(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set) {
    if (!set || set->programs.empty()) return;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, set->header), 0, VK_WHOLE_SIZE, 0);
}

void recordProgramListsSetup(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set) {
    if (!set || set->programs.empty()) return;
    bind(gpu, cmd, set->setup);
    pushConstants(gpu, cmd,
                  ListsSetupPush{address(gpu, set->header), uint32_t(set->programs.size())});
    vkCmdDispatch(cmd, 1, 1, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                      VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}

void recordMaterialProgramStages(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set,
                                 uint64_t frame) {
    if (!set || set->programs.empty()) return;
    StagePush push{frame, address(gpu, set->header), address(gpu, set->queues), 0, set->capacity};
    // After the built-in program's shading: with spectra it shades the whole queue, these
    // chunks too, and the stages write over it.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    size_t longest = 0;
    for (const std::vector<Pipeline>& stages : set->stages)
        longest = std::max(longest, stages.size());
    // Stage s of every program, then a barrier: stage s + 1 reads the layers stage s wrote.
    // Programs' lists are disjoint, so their stages need no barrier between them.
    for (size_t s = 0; s < longest; ++s) {
        if (s > 0)
            memoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        for (uint32_t p = 0; p < set->programs.size(); ++p) {
            if (s >= set->stages[p].size()) continue;
            push.program = p;
            bind(gpu, cmd, set->stages[p][s]);
            pushConstants(gpu, cmd, push);
            vkCmdDispatchIndirect(cmd, vkBuffer(gpu, set->header), VkDeviceSize(p) * 16);
        }
    }
}

uint32_t pollMaterialPrograms(Gpu& gpu, MaterialProgramSet* set, std::vector<std::string>& errors,
                              std::vector<uint8_t>& reshade) {
    if (!set) return 0;
    uint32_t swapped = 0;
    for (size_t p = 0; p < set->programs.size(); ++p) {
        if (fileStamps(set->programs[p]) == set->stamps[p]) continue;
        set->stamps[p] = fileStamps(set->programs[p]); // a failed edit is reported once
        MaterialProgram fresh;
        std::vector<Pipeline> pipelines;
        try {
            pipelines = buildProgram(gpu, set->programs[p].path, fresh);
        } catch (const std::exception& e) {
            SHADEL_ERROR("material program reload: %s (the last good program stays)", e.what());
            errors.push_back(e.what());
            continue;
        }
        vkDeviceWaitIdle(gpu.device.device); // the old pipelines may still be in flight
        for (Pipeline& old : set->stages[p]) destroy(gpu, old);
        set->stages[p] = std::move(pipelines);
        set->programs[p] = std::move(fresh);
        set->stamps[p] = fileStamps(set->programs[p]);
        reshade.resize(std::max(reshade.size(), set->programOfMaterial.size()), 0);
        for (size_t m = 0; m < set->programOfMaterial.size(); ++m)
            if (set->programOfMaterial[m] == p + 1) reshade[m] = 1;
        ++swapped;
    }
    return swapped;
}

void finishMaterialProgramsFrame(const Gpu& gpu, MaterialProgramSet* set, uint32_t shadedChunks) {
    if (!set) return;
    uint64_t programChunks = 0;
    if (!set->programs.empty()) {
        const auto* header = static_cast<const uint32_t*>(mapped(gpu, set->header));
        for (size_t p = 0; p < set->programs.size(); ++p) {
            set->chunks[p + 1] += header[p * 4 + 3];
            programChunks += header[p * 4 + 3];
        }
    }
    set->chunks[0] += shadedChunks > programChunks ? shadedChunks - programChunks : 0;
    set->frames++;
}

void materialProgramStats(const MaterialProgramSet* set, nlohmann::json& stats) {
    nlohmann::json list = nlohmann::json::array();
    if (!set) {
        stats["material_programs"] = list;
        return;
    }
    double frames = double(std::max<uint64_t>(set->frames, 1));
    auto perFrame = [&](size_t index) { return double(set->chunks[index]) * 64.0 / frames; };
    if (set->chunks[0] > 0) // the built-in program: shadel/shade.comp, one stage
        list.push_back({{"name", "gltf_pbr"},
                        {"builtin", true},
                        {"rate", "on_change"},
                        {"stages", {"shade"}},
                        {"layers", {"radiance", "material"}},
                        {"shadels_per_stage", {perFrame(0)}}});
    for (size_t p = 0; p < set->programs.size(); ++p) {
        const MaterialProgram& program = set->programs[p];
        nlohmann::json stages = nlohmann::json::array(), layers = nlohmann::json::array(),
                       shadels = nlohmann::json::array();
        for (const MaterialStage& s : program.stages) {
            stages.push_back(s.name);
            shadels.push_back(perFrame(p + 1));
        }
        for (uint32_t l : program.layers) layers.push_back(kMaterialLayerNames[l]);
        list.push_back({{"name", program.name},
                        {"builtin", false},
                        {"rate", program.everyFrame ? "every_frame" : "on_change"},
                        {"stages", stages},
                        {"layers", layers},
                        {"shadels_per_stage", shadels}});
    }
    stats["material_programs"] = list;
}

} // namespace shadel
