#pragma once
// The decoupled path's material programs (material_program.h) on the GPU: each loaded program's
// stages as compute pipelines, and the program lists the work queue fill routes their objects'
// chunks to. The built-in glTF PBR program keeps its shading classes and spectra permutations
// (shaders/shadel/shade.comp); every other program's stages run in order as indirect dispatches
// over its own list, after the built-in program's.
#include <memory>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rhi/gpu.h"

namespace shadel {

struct GpuScene;
struct MaterialProgramSet;
struct MaterialProgramSetDeleter {
    void operator()(MaterialProgramSet* set) const;
};
using MaterialProgramSetPtr = std::unique_ptr<MaterialProgramSet, MaterialProgramSetDeleter>;

// Loads and compiles the programs the scene's materials name (GpuScene::materialPrograms), each
// once (a set of none when every material uses the built-in program). Throws InputError (file,
// reason; a stage's compile error as file:line) on a bad program.
MaterialProgramSetPtr createMaterialPrograms(Gpu& gpu, const GpuScene& scene,
                                             uint32_t capacityChunks);
void destroyMaterialPrograms(Gpu& gpu, MaterialProgramSetPtr& set);

// The bits of a decoupled object's GpuShadelObject flags that name its material's program
// (SHADEL_OBJECT_PROGRAM_SHIFT; 0 for the built-in program).
uint32_t materialProgramFlags(const MaterialProgramSet* set, uint32_t material);

// The push constants of the work queue fill and near-change passes: the frame and the program
// lists' addresses (0 when no program is loaded).
struct ProgramListsPush {
    uint64_t frame = 0, header = 0, queues = 0;
};
ProgramListsPush programListsPush(const Gpu& gpu, const MaterialProgramSet* set, uint64_t frame);

// Zeroes the lists' counts (before the work queue fill; a transfer write).
void recordProgramListsClear(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set);
// The lists' indirect arguments from their counts (after the fill, and after the near-change
// pass), followed by a compute-to-compute and indirect barrier.
void recordProgramListsSetup(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set);
// Every program's stages in order over its list, with a barrier between stages.
void recordMaterialProgramStages(const Gpu& gpu, VkCommandBuffer cmd, const MaterialProgramSet* set,
                                 uint64_t frame);

// Hot reload (the viewer): recompiles every program whose .shmat, common or stage file changed
// (time stamp or size) and swaps its pipelines, waiting for the device to idle first. A program
// that fails to load or compile keeps its last good pipelines; its error (file:line for a
// stage) is returned in `errors`. The materials of a swapped program are set in `reshade` (per
// material, resized to the material count), so their carried-over chunks are shaded again.
// Returns the programs swapped.
uint32_t pollMaterialPrograms(Gpu& gpu, MaterialProgramSet* set, std::vector<std::string>& errors,
                              std::vector<uint8_t>& reshade);

// After the GPU finished the frame: adds its list lengths to the statistics; `shadedChunks` is
// the frame's whole shading queue (the built-in program's share is what the programs left).
void finishMaterialProgramsFrame(const Gpu& gpu, MaterialProgramSet* set, uint32_t shadedChunks);
// "material_programs": per program that ran, its name, stages, layers and the shadels each stage
// ran on per frame (a mean over the frames so far; 64 per chunk of its list).
void materialProgramStats(const MaterialProgramSet* set, nlohmann::json& stats);

} // namespace shadel
