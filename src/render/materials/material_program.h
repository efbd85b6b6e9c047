#pragma once
// Material programs: a material is a program of layer stages, compute stages over its objects'
// shadels that read like pixel shaders to their author. A program is a `.shmat` JSON file
// naming the engine layers it uses, its parameters with their defaults and its stages in order,
// each a GLSL file; the engine puts its own preamble before each stage (the shadel's storage,
// the surface point rebuilt from the mesh, the parameters, readLayer / writeLayer and the
// scene's lighting) and compiles it when the scene loads. docs/materials.md teaches writing one.
#include <array>
#include <string>
#include <vector>

namespace shadel {

// The engine's layers, in the order of the shade storage (SHADEL_LAYER_*): what a program's
// "layers" may name. Reconstruction reads radiance, so every program writes it last.
inline constexpr const char* kMaterialLayerNames[] = {"radiance", "material"};

struct MaterialParameter {
    std::string name;             // a GLSL identifier: a constant in every stage
    std::array<float, 4> value{}; // its default
    uint32_t components = 1;      // 1: float, 2..4: vec2..vec4
};

struct MaterialStage {
    std::string name; // as the stats name it
    std::string path; // the GLSL file, resolved next to the .shmat
};

struct MaterialProgram {
    std::string name;
    std::string path;             // the .shmat
    std::vector<uint32_t> layers; // indices into kMaterialLayerNames, ascending
    std::vector<MaterialParameter> parameters;
    std::vector<MaterialStage> stages;
    std::string common; // a GLSL file every stage sees before its own ("" = none)
    // "rate": "on_change" (false: its chunks are carried over while their inputs are unchanged,
    // as the built-in program's) or "every_frame" (true: shaded every frame they are seen, for
    // stages that accumulate samples through prevSample).
    bool everyFrame = false;
};

// "builtin:NAME" names a program shipped with the engine (shaders/materials/programs/NAME.shmat);
// anything else is a path. Returns the file to read.
std::string materialProgramFile(const std::string& reference);

// Reads and checks a .shmat (and that its stage files exist). Throws InputError, one line
// "<file>: <reason>", on a bad file.
MaterialProgram loadMaterialProgram(const std::string& path);

// The GLSL compiled for stage `stage` of the program: the engine's preamble, the parameters and
// layer names, the author's file (after a #line directive, so the compiler's messages name the
// stage file and its own lines) with its main() renamed, and the engine's main.
std::string materialStageSource(const MaterialProgram& program, uint32_t stage);

// Compiles every stage to SPIR-V with glslc (shaderc's compiler, as the build runs it; the
// engine's shader sources under `shaderSourceDir` are its include path). Throws InputError with
// the compiler's first error, "<stage file>:<line>: error: ...", when a stage does not compile.
std::vector<std::vector<uint32_t>> compileMaterialProgram(const MaterialProgram& program,
                                                          const std::string& shaderSourceDir);

} // namespace shadel
